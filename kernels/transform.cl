// Basis transform: depth z (W*H floats) -> SF_CHANNELS planes of basis values.
// Needs storage.clh and a method header (sf_basis, sf_basisv, sf_method_params, SF_CHANNELS)
// before it. The method's basis already maps into [0,1] for unorm storage (its vector basis may
// give code units instead, SF_BASISV_CODES); the stores round.

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

// SF_XVEC values of one plane, rounded as sf_store rounds them (unorm: within one code at ties,
// below). f16: vcvtps2ph, round to nearest even like vstore_half_rte. On x86 with AVX-512 the
// conversion is an asm statement with a register result: from vstore_half16_rte LLVM folds the
// store into vcvtps2ph's memory form, which some x86 cores run slower (docs/methods.md,
// "storage"); elsewhere vstore_halfn_rte (vector code in PoCL; the scalar vstore_half is a call
// per texel).
// Unorm: the value in code units plus 1.5 * 2^23 holds the nearest integer (ties to even, as
// rint) in its low mantissa bits, cheaper than a float -> integer conversion. A method that
// defines SF_BASISV_CODES gives code units in (-0.5, max + 0.5) from sf_basisv (csm: see its
// header); otherwise the value in [0,1] is clamped and scaled with contraction off, so the
// product is rounded first as in sf_store.
inline void sf_store_planev(__global sf_stored* p, sf_xfloat v) {
#pragma OPENCL FP_CONTRACT OFF
#if SF_STORAGE == SF_STORAGE_F32
  *(__global sf_xfloat_u*)p = v;
#elif SF_STORAGE == SF_STORAGE_F16
#if defined(__x86_64__) && defined(__AVX512F__) && SF_XVEC == 16
  SF_CAT(ushort, SF_XVEC) h;
  __asm__("vcvtps2ph $0, %1, %0" : "=v"(h) : "v"(v));
  *(__global sf_xushort_u*)p = h;
#else
  SF_CAT(SF_CAT(vstore_half, SF_XVEC), _rte)(v, 0, p);
#endif
#else
#ifdef SF_BASISV_CODES
  const sf_xfloat t = v + 12582912.0f;
#else
  const sf_xfloat t = clamp(v, 0.0f, 1.0f) * SF_UNORM_MAX + 12582912.0f;
#endif
#if SF_STORAGE == SF_STORAGE_UNORM16
  *(__global sf_xushort_u*)p = SF_CAT(convert_ushort, SF_XVEC)(SF_CAT(as_uint, SF_XVEC)(t));
#else
  *(__global sf_xuchar_u*)p = SF_CAT(convert_uchar, SF_XVEC)(SF_CAT(as_uint, SF_XVEC)(t));
#endif
#endif
}

// Vectors per work-item (SF_XREP): with more than 4 planes, enough for one whole 64-byte cache
// line of every plane. The planes lie plane_stride texels apart, the same offset modulo 4 KiB
// when the stride is a power of two, so they share one L1 set (8 ways): with one 16-byte unorm8
// vector per plane and work-item, the 2M + 1 streams of csm evicted each line before the next
// work-item filled it, and csm M = 16 unorm8 (36 B per texel) took as long as float32 (132 B).
// Written plane by plane, a line is complete before the next plane's. Up to 4 planes (5 streams)
// the lines survive, and one vector per item is faster (esm f16 took 20% longer with 2 vectors
// per item). The host (enqueue_transform) picks SF_XREP by this rule and launches one work-item
// per SF_XVEC SF_XREP texels.
#ifndef SF_XREP
#define SF_XREP 1
#endif

// The default path: SF_XREP runs of SF_XVEC consecutive texels per work-item, one vector load of
// depths per run, the method's vector basis (sf_basisv), then plane by plane one vector store per
// run. A method whose planes come out of a recurrence in pairs (SF_BASISV_PAIRS: csm) is stepped
// on all runs together and stored as it goes, so the planes of every run need not stay live
// (they spill at high orders); not in float32 (one vector is a whole line there, and plane order
// 0, 1, 2, ... stores faster than pair order). docs/methods.md, "storage", has the figures.
// PoCL vectorises the one-texel kernel below across work-items only when it is simple (one exp,
// float stores); explicit vectors keep exp, the csm recurrence and the narrow stores in vector
// code for every method.
// Launch: ceil(texels / (SF_XVEC SF_XREP)) work-items or more (items past the end return). The
// one holding the end of a partial run finishes it texel by texel with the scalar basis and
// sf_store (same values within an ulp of exp, see the method headers; unorm codes within one at
// ties).
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_transformv)
__kernel void sf_transformv(__global const float* restrict depth, __global sf_stored* restrict basis,
                            const int texels, const int plane_stride, const sf_method_params P) {
  const size_t i0 = get_global_id(0) * (size_t)(SF_XVEC * SF_XREP);
  if (i0 >= (size_t)texels) return;
  if (i0 + SF_XVEC * SF_XREP > (size_t)texels) {
    float b[SF_CHANNELS];
    for (size_t i = i0; i < (size_t)texels; ++i) {
      sf_basis(depth[i], P, b);
      sf_store_basis(basis, plane_stride, i, b);
    }
    return;
  }
#if defined(SF_BASISV_PAIRS) && SF_STORAGE != 0
  sf_basisv_state st[SF_XREP];
#pragma unroll
  for (int r = 0; r < SF_XREP; ++r)
    st[r] = sf_basisv_start(*(__global const sf_xfloat_u*)(depth + i0 + r * SF_XVEC), P);
#pragma unroll
  for (int k = 0; k < SF_BASISV_PAIRS; ++k) {
    sf_xfloat a[SF_XREP], b[SF_XREP];
#pragma unroll
    for (int r = 0; r < SF_XREP; ++r) sf_basisv_step(&st[r], &a[r], &b[r]);
#pragma unroll
    for (int r = 0; r < SF_XREP; ++r)
      sf_store_planev(basis + k * (size_t)plane_stride + i0 + r * SF_XVEC, a[r]);
#pragma unroll
    for (int r = 0; r < SF_XREP; ++r)
      sf_store_planev(basis + (SF_BASISV_PAIRS + k) * (size_t)plane_stride + i0 + r * SF_XVEC,
                      b[r]);
  }
#else
  sf_xfloat b[SF_XREP][SF_CHANNELS];
#pragma unroll
  for (int r = 0; r < SF_XREP; ++r)
    sf_basisv(*(__global const sf_xfloat_u*)(depth + i0 + r * SF_XVEC), P, b[r]);
#pragma unroll
  for (int c = 0; c < SF_CHANNELS; ++c)
#pragma unroll
    for (int r = 0; r < SF_XREP; ++r)
      sf_store_planev(basis + c * (size_t)plane_stride + i0 + r * SF_XVEC, b[r][c]);
#endif
}
#endif

// One texel per work-item (schedule transform_vector_width = 1): the scalar baseline the
// benchmarks compare with. The global size is `texels`, or rounded up to a multiple of the
// work-group size when the caller fixes one. The exact launch has its own branch without a
// per-item bounds check: the condition is uniform, so the compiler unswitches the work-item loop
// and the vectorised loop has no masked loads and stores. In the padded launch, padding items
// transform 0 and store nothing; the two branches are written differently on purpose, so that
// they are not merged back into one masked loop.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_transform)
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
#endif
