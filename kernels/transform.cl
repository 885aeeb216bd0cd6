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


// Vector path for 16- and 8-bit storage: a work-item transforms 16 consecutive texels and writes
// each plane's 16 values with one vector store, converting them together (vstore_half16_rte;
// unorm: rint of the clamped value, equal to convert_*_sat_rte, which PoCL does not vectorise). PoCL does not vectorise the one-texel kernel across work-items when it
// stores narrow types, and the scalar conversions cost 5-20x the float32 transform.
// Launch: ceil(texels / 16) work-items; the last one finishes a partial run texel by texel.
__kernel void sf_transform16(__global const float* restrict depth, __global sf_stored* restrict basis,
                             const int texels, const int plane_stride, const sf_method_params P) {
  const size_t i0 = get_global_id(0) * (size_t)16;
  if (i0 >= (size_t)texels) return;
  if (i0 + 16 > (size_t)texels) {
    float b[SF_CHANNELS];
    for (size_t i = i0; i < (size_t)texels; ++i) {
      sf_basis(depth[i], P, b);
      sf_store_basis(basis, plane_stride, i, b);
    }
    return;
  }
  float z[16];
  vstore16(vload16(0, depth + i0), 0, z);
  float planes[SF_CHANNELS][16];
#pragma unroll
  for (int t = 0; t < 16; ++t) {
    float b[SF_CHANNELS];
    sf_basis(z[t], P, b);
#pragma unroll
    for (int c = 0; c < SF_CHANNELS; ++c) planes[c][t] = b[c];
  }
#pragma unroll
  for (int c = 0; c < SF_CHANNELS; ++c) {
    __global sf_stored* p = basis + c * (size_t)plane_stride + i0;
    const float16 v = vload16(0, planes[c]);
#if SF_STORAGE == 0
    vstore16(v, 0, p);
#elif SF_STORAGE == 1
    vstore_half16_rte(v, 0, p);
#elif SF_STORAGE == 2
    vstore16(convert_ushort16(rint(clamp(v, 0.0f, 1.0f) * 65535.0f)), 0, p);  // = _sat_rte
#else
    vstore16(convert_uchar16(rint(clamp(v, 0.0f, 1.0f) * 255.0f)), 0, p);
#endif
  }
}
