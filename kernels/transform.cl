// Basis transform: depth z (W*H floats) -> SF_CHANNELS planes of basis values.
// Needs storage.clh and a method header (sf_basis, sf_basisv, sf_method_params, SF_CHANNELS)
// before it. The method's basis already maps into [0,1] for unorm storage; the stores round.

inline void sf_store_basis(__global sf_stored* restrict basis, int plane_stride, size_t i,
                           const float* b) {
#pragma unroll
  for (int c = 0; c < SF_CHANNELS; ++c) sf_store(basis + c * (size_t)plane_stride, i, b[c]);
}

// Vectors aligned to one element: a plane starts anywhere (plane_stride = texels). PoCL's
// vstoren of integer types writes element by element (16 byte stores for unorm8), and vloadn /
// vstoren of floats are no faster than these.
typedef sf_xfloat __attribute__((aligned(4))) sf_xfloat_u;
typedef SF_CAT(ushort, SF_XVEC) __attribute__((aligned(2))) sf_xushort_u;
typedef SF_CAT(uchar, SF_XVEC) __attribute__((aligned(1))) sf_xuchar_u;

// SF_XVEC values of one plane, rounded as sf_store rounds them. f16: vstore_halfn_rte, vector
// code in PoCL (the scalar vstore_half is a call per texel). Unorm: the clamped, scaled value plus
// 1.5 * 2^23 holds the nearest integer (ties to even, as rint) in its low mantissa bits, cheaper
// than a float -> integer conversion; contraction is off so the product is rounded first, as in
// sf_store (an fma would round once and differ by one code near ties).
inline void sf_store_planev(__global sf_stored* p, sf_xfloat v) {
#pragma OPENCL FP_CONTRACT OFF
#if SF_STORAGE == 0
  *(__global sf_xfloat_u*)p = v;
#elif SF_STORAGE == 1
  SF_CAT(SF_CAT(vstore_half, SF_XVEC), _rte)(v, 0, p);
#elif SF_STORAGE == 2
  const sf_xfloat t = clamp(v, 0.0f, 1.0f) * 65535.0f + 12582912.0f;
  *(__global sf_xushort_u*)p = SF_CAT(convert_ushort, SF_XVEC)(SF_CAT(as_uint, SF_XVEC)(t));
#else
  const sf_xfloat t = clamp(v, 0.0f, 1.0f) * 255.0f + 12582912.0f;
  *(__global sf_xuchar_u*)p = SF_CAT(convert_uchar, SF_XVEC)(SF_CAT(as_uint, SF_XVEC)(t));
#endif
}

// The default path: SF_XVEC consecutive texels per work-item, one vector load of depths, the
// method's vector basis (sf_basisv), one vector store per plane. PoCL vectorises the one-texel
// kernel below across work-items only when it is simple (one exp, float stores); explicit vectors
// keep exp, the csm recurrence and the narrow stores in vector code for every method.
// Launch: ceil(texels / SF_XVEC) work-items or more (padding items return); the one holding the
// end of a partial run finishes it texel by texel with the scalar basis (same values within an
// ulp of exp, see the method headers).
__kernel void sf_transformv(__global const float* restrict depth, __global sf_stored* restrict basis,
                            const int texels, const int plane_stride, const sf_method_params P) {
  const size_t i0 = get_global_id(0) * (size_t)SF_XVEC;
  if (i0 >= (size_t)texels) return;
  if (i0 + SF_XVEC > (size_t)texels) {
    float b[SF_CHANNELS];
    for (size_t i = i0; i < (size_t)texels; ++i) {
      sf_basis(depth[i], P, b);
      sf_store_basis(basis, plane_stride, i, b);
    }
    return;
  }
  sf_xfloat b[SF_CHANNELS];
  sf_basisv(*(__global const sf_xfloat_u*)(depth + i0), P, b);
#pragma unroll
  for (int c = 0; c < SF_CHANNELS; ++c) sf_store_planev(basis + c * (size_t)plane_stride + i0, b[c]);
}

// One texel per work-item (schedule transform_vector_width = 1): the scalar baseline the
// benchmarks compare with. The global size is `texels`, or rounded up to a multiple of the
// work-group size when the caller fixes one. The exact launch has its own branch without a
// per-item bounds check: the condition is uniform, so the compiler unswitches the work-item loop
// and the vectorised loop has no masked loads and stores. In the padded launch, padding items
// transform 0 and store nothing; the two branches are written differently on purpose, so that
// they are not merged back into one masked loop.
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
