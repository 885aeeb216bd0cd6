// cssm: convolution soft shadows (seed 000 ch. 8; methods.md sec. 4). Needs common.clh,
// storage.clh (SF_STORAGE 0), lookup.clh and soft/soft_common.clh before it; SF_CSSM_ORDER = M.
// Basis (4M + 1 float32 planes), c_k = (2k - 1) pi:
//   [0, M) sin(c_k z), [M, 2M) cos(c_k z)          the CSM basis (same as methods/csm.clh)
//   [2M, 3M) z sin(c_k z), [3M, 4M) z cos(c_k z)   CSM-Z (eq. 8.8)
//   4M: z / 2                                      the constant term of eq. 8.8
// Reconstruction per receiver, d' = d - offset (stage 1: d - z_offset):
//   stage 1: lookup at the search width w(d, 0) (the light's footprint at the near plane);
//     s_f  = 1/2 + 2 sum_k [cos(c_k d') bar(sin_k) - sin(c_k d') bar(cos_k)] / c_k
//     z_avg = [bar(z/2) + 2 sum_k (sin(c_k d') bar(z cos_k) - cos(c_k d') bar(z sin_k)) / c_k]
//             / (1 - s_f)                          (eq. 8.8 over eq. 8.6's normalisation)
//     1 - s_f < min_den: no blocker in the search region, lit (1) (guards the division).
//   stage 2: f_w = w(d, z_avg) (sec. 8.3.1), CSM lookup at max(f_w, f, 1) texels;
//     v = clamp(0.5 + scale (s_f - 0.5), 0, 1)    (ringing suppression: scale, shift, clamp)
//     v = v^p, p = 1 + A exp(-B (d - z_avg))       (eq. 8.9; A = 0: off)
#ifndef SF_CSSM_ORDER
#error "cssm needs SF_CSSM_ORDER"
#endif
#define SF_M SF_CSSM_ORDER
// Trilinear (mips) lookups read at LOD log2(SF_CSSM_MIP_SCALE w): the 2x2 mean of the pyramid
// and the bilinear tent each blur by about the level's texel, so level log2(w) filters far wider
// than the box of side w; 0.55 matches the box's spread (docs/soft.md, parallel-planes test).
#if SF_LOOKUP == 1
#define SF_CSSM_MIP_SCALE 0.55f
#else
#define SF_CSSM_MIP_SCALE 1.0f
#endif

typedef struct {
  float offset, scale, sharpen_a, sharpen_b, min_den, z_offset;
} sf_cssm_params;

__kernel void sf_cssm_basis(__global const float* restrict depth, __global float* restrict basis,
                            const int texels) {
  const int i = get_global_id(0);
  if (i >= texels) return;
  const float z = depth[i];
  float c1;
  const float s1 = sincos(M_PI_F * z, &c1);
  const float s2 = 2.0f * s1 * c1, c2 = fma(-2.0f * s1, s1, 1.0f);
  float s = s1, c = c1;
  const size_t P = (size_t)texels;
  for (int k = 0; k < SF_M; ++k) {
    basis[k * P + i] = s;
    basis[(SF_M + k) * P + i] = c;
    basis[(2 * SF_M + k) * P + i] = z * s;
    basis[(3 * SF_M + k) * P + i] = z * c;
    const float sn = fma(s, c2, c * s2);
    c = fma(c, c2, -s * s2);
    s = sn;
  }
  basis[4 * SF_M * P + i] = 0.5f * z;
}

// s_f (and, when num != 0, the CSM-Z numerator) from filtered values b at receiver depth d'.
inline float sf_cssm_series(const float* b, float dp, float* num) {
  float c1;
  const float s1 = sincos(M_PI_F * dp, &c1);
  const float s2 = 2.0f * s1 * c1, c2 = fma(-2.0f * s1, s1, 1.0f);
  float s = s1, c = c1, sf = 0.0f, sz = 0.0f;
  for (int k = 0; k < SF_M; ++k) {
    const float ick = 1.0f / ((2 * k + 1) * M_PI_F);
    sf = fma(ick, c * b[k] - s * b[SF_M + k], sf);
    if (num) sz = fma(ick, s * b[3 * SF_M + k] - c * b[2 * SF_M + k], sz);
    const float sn = fma(s, c2, c * s2);
    c = fma(c, c2, -s * s2);
    s = sn;
  }
  if (num) *num = fma(2.0f, sz, b[4 * SF_M]);
  return fma(2.0f, sf, 0.5f);
}

__kernel void sf_cssm_points(__global const float* restrict basis, const int W, const int H,
                             __global const float* restrict chain, __global const float* restrict sat,
                             __global const float* restrict u, __global const float* restrict v,
                             __global const float* restrict d, __global const float* restrict f,
                             __global float* restrict out, __global float* restrict zavg_out,
                             const int count, const sf_soft_light L, const sf_cssm_params P) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    out[i] = 1.0f;
    if (zavg_out) zavg_out[i] = NAN;
    return;
  }
  const float dd = clamp(di, 0.0f, 1.0f), dp = dd - P.offset;
  const float fp = f ? (isfinite(f[i]) ? f[i] : 1.0f) : 1.0f;
  float b[SF_CHANNELS];
  const float search = clamp(fmax(sf_soft_width(L, dd, 0.0f) * (float)W, fp), 1.0f, L.max_width);
  sf_lookup(basis, chain, sat, W, H, ui, vi, SF_CSSM_MIP_SCALE * search, b);
  float num;
  // Stage 1 at d - z_offset (0.5 / M): there a lit texel (z = d) gives 1 - f ~ -0.09, close to
  // 0; at the visibility offset it would count as a quarter blocker at depth d.
  const float den = 1.0f - sf_cssm_series(b, dd - P.z_offset, &num);
  if (!(den >= P.min_den)) {  // also catches NaN
    out[i] = 1.0f;
    if (zavg_out) zavg_out[i] = NAN;
    return;
  }
  const float zavg = clamp(num / den, 0.0f, dd);
  if (zavg_out) zavg_out[i] = zavg;
  const float fw = clamp(fmax(sf_soft_width(L, dd, zavg) * (float)W, fp), 1.0f, L.max_width);
  sf_lookup(basis, chain, sat, W, H, ui, vi, SF_CSSM_MIP_SCALE * fw, b);
  float vis = clamp(fma(P.scale, sf_cssm_series(b, dp, 0) - 0.5f, 0.5f), 0.0f, 1.0f);
  if (P.sharpen_a > 0.0f) vis = pow(vis, 1.0f + P.sharpen_a * exp(-P.sharpen_b * (dd - zavg)));
  out[i] = vis;
}
