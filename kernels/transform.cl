// Basis transform: depth z (W*H floats) -> SF_CHANNELS planes of basis values.
// Needs storage.clh and a method header (sf_basis, sf_method_params, SF_CHANNELS) before it.
// The method's sf_basis already maps into [0,1] for unorm storage; sf_store rounds.

inline void sf_store_basis(__global sf_stored* restrict basis, int plane_stride, size_t i,
                           const float* b) {
#pragma unroll
  for (int c = 0; c < SF_CHANNELS; ++c) sf_store(basis + c * (size_t)plane_stride, i, b[c]);
}

// One texel per work-item. The global size is `texels`, or rounded up to a multiple of the
// work-group size when the caller fixes one. The exact launch (the usual one) has its own
// branch without a per-item bounds check: the condition is uniform, so the compiler unswitches
// the work-item loop and the vectorised loop has no masked loads and stores (about 20% faster
// on PoCL). In the padded launch, padding items transform 0 and store nothing; the two branches
// are written differently on purpose, so that they are not merged back into one masked loop.
__kernel void sf_transform(__global const float* restrict depth, __global sf_stored* restrict basis,
                           const int texels, const int plane_stride, const sf_method_params P) {
  const size_t i = get_global_id(0);
  const size_t n = (size_t)texels;
  float b[SF_CHANNELS];
  if (get_global_size(0) == n) {
    sf_basis(depth[i], P, b);
    sf_store_basis(basis, plane_stride, i, b);
    return;
  }
  sf_basis(i < n ? depth[i] : 0.0f, P, b);
  if (i < n) sf_store_basis(basis, plane_stride, i, b);
}
