// cssm: convolution soft shadows (Annen 2008 ch. 8; methods.md sec. 4). Needs common.clh,
// storage.clh, lookup.clh and soft/soft_common.clh before it; SF_CSSM_ORDER = M.
// Basis (4M + 1 planes in SF_STORAGE: float32, or f16 / unorm16 / unorm8 with mips only, the
// SAT's table being float-float whatever its input), c_k = (2k - 1) pi:
//   [0, M) sin(c_k z), [M, 2M) cos(c_k z)          the CSM basis (same as methods/csm.clh)
//   [2M, 3M) z sin(c_k z), [3M, 4M) z cos(c_k z)   CSM-Z (eq. 8.8)
//   4M: z / 2                                      the constant term of eq. 8.8
// Every plane lies in [-1, 1]; unorm storage holds 0.5 + 0.5 b (exactly [0, 1]), and since the
// mean pyramid and the trilinear weights are affine, a lookup maps its result back by 2 x - 1.
// Reconstruction per receiver, d' = d - offset (stage 1: d - z_offset); parameters resolved on
// the host (soft_filter.cpp cssm_params; docs/soft.md "cssm defaults"):
//   stage 1: lookup of all planes over the search footprint w(d, 0) (the light's rectangle at the
//     near plane), at d - z_offset where a lit texel (z = d) reconstructs to 1 (weight 0 in z_avg);
//     s_f  = 1/2 + 2 sum_k [cos(c_k d') bar(sin_k) - sin(c_k d') bar(cos_k)] / c_k
//     z_avg = [bar(z/2) + 2 sum_k (sin(c_k d') bar(z cos_k) - cos(c_k d') bar(z sin_k)) / c_k]
//             / (1 - s_f)                          (eq. 8.8 over eq. 8.6's normalisation)
//     1 - s_f < min_den (or NaN): no blocker beyond z_offset, no division; z_avg = d (contact):
//     stage 2 still runs at the receiver's footprint (contact = 0: lit, return 1).
//   stage 2: f_w = width_scale w(d, z_avg) (sec. 8.3.1), lookup of the 2M CSM planes over
//     max(f_w, f, 1) texels on each side; v = clamp(0.5 + scale (s_f inv_lit - 0.5), 0, 1) (ringing
//     suppression: scale, shift, clamp), then v^p, p = 1 + A exp(-B (d - z_avg)) (eq. 8.9).
#ifndef SF_CSSM_ORDER
#error "cssm needs SF_CSSM_ORDER"
#endif
#define SF_M SF_CSSM_ORDER
// Trilinear (mips) lookups read at LOD log2(SF_CSSM_MIP_SCALE w): the 2x2 mean of the pyramid
// and the bilinear tent each blur by about the level's texel, so level log2(w) filters far wider
// than the box of side w; 0.55 matches the box's spread at the default width scale (parallel
// planes, docs/soft.md; mips stay alignment-dependent).
#if SF_LOOKUP == SF_LOOKUP_MIPS
#define SF_CSSM_MIP_SCALE 0.55f
#else
#define SF_CSSM_MIP_SCALE 1.0f
#endif
// A footprint fx x fy texels (a rectangular light's) reads the SAT's rectangle exactly; the mips
// read it as hardware anisotropic filtering does: n = ceil(long / short) trilinear probes (at most
// SF_CSSM_MAX_PROBES; ratios within 1% of 1 take one) at the centres of n equal parts of the
// long side, each at the LOD of max(short, long / n), averaged.
#define SF_CSSM_MAX_PROBES 8

// ---- Lookups of the first nch planes (stage 2 reads only the 2M CSM planes). The same math as
// lookup.clh's trilinear and box lookups (host/reference LookupRef checks both), except that
// the SAT is read from sf_cssm_sat_pack's texel-interleaved copy: one receiver's 4 corners of
// all planes are 4 x 2 runs of 2 nch (hi, lo) pairs instead of 4 nch scattered planes.
#if SF_STORAGE_UNORM
#define SF_CSSM_ENCODE(b) fma(0.5f, (b), 0.5f)
#define SF_CSSM_DECODE(x) fma(2.0f, (x), -1.0f)
#else
#define SF_CSSM_ENCODE(b) (b)
#define SF_CSSM_DECODE(x) (x)
#endif

inline void sf_cssm_bilinear(__global const sf_stored* restrict img, int width, int height, float u, float v,
                             int nch, float* out) {
  const float x = fma(u, (float)width, -0.5f);
  const float y = fma(v, (float)height, -0.5f);
  const float xf = floor(x), yf = floor(y);
  const float ax = x - xf, ay = y - yf;
  const int x0 = sf_clampi((int)xf, 0, width - 1), x1 = sf_clampi((int)xf + 1, 0, width - 1);
  const int y0 = sf_clampi((int)yf, 0, height - 1), y1 = sf_clampi((int)yf + 1, 0, height - 1);
  const size_t i00 = (size_t)y0 * width + x0, i01 = (size_t)y0 * width + x1;
  const size_t i10 = (size_t)y1 * width + x0, i11 = (size_t)y1 * width + x1;
  const size_t plane = (size_t)width * height;
  for (int c = 0; c < nch; ++c) {
    __global const sf_stored* p = img + (size_t)c * plane;
    const float top = mix(sf_load(p, i00), sf_load(p, i01), ax);
    const float bottom = mix(sf_load(p, i10), sf_load(p, i11), ax);
    out[c] = mix(top, bottom, ay);
  }
}

inline void sf_cssm_level(__global const sf_stored* restrict level0, __global const sf_stored* restrict chain, int W,
                          int H, int k, float u, float v, int nch, float* out) {
  if (k == 0) {
    sf_cssm_bilinear(level0, W, H, u, v, nch, out);
    return;
  }
  int w, h;
  size_t off;
  sf_mip_level(W, H, SF_CHANNELS, k, &w, &h, &off);
  sf_cssm_bilinear(chain + off, w, h, u, v, nch, out);
}

// The pair (hi, lo) of plane c at SAT entry e of the packed table.
#define SF_PK(e, c) ((float2)(pk[2 * ((e) * SF_CHANNELS + (c))], pk[2 * ((e) * SF_CHANNELS + (c)) + 1]))

inline float2 sf_cssm_sat_at(__global const float* restrict pk, int W, int H, float X, float Y, int c) {
  const int i = clamp((int)floor(X), 0, W - 1), j = clamp((int)floor(Y), 0, H - 1);
  const float fx = X - (float)i, fy = Y - (float)j;
  const size_t Wp = (size_t)W + 1, a = (size_t)j * Wp + i, e = a + Wp;
  const float2 s00 = SF_PK(a, c), s10 = SF_PK(a + 1, c), s01 = SF_PK(e, c), s11 = SF_PK(e + 1, c);
  const float2 dx = sf_dd_sum(s10, -s00), dy = sf_dd_sum(s01, -s00);
  const float2 dxy = sf_dd_sum(sf_dd_sum(s11, -s01), -dx);
  float2 r = sf_dd_sum(s00, sf_dd_scale(dx, fx));
  r = sf_dd_sum(r, sf_dd_scale(dy, fy));
  return sf_dd_sum(r, sf_dd_scale(sf_dd_scale(dxy, fx), fy));
}

#if SF_LOOKUP == SF_LOOKUP_MIPS
// One trilinear probe of footprint f texels, added into acc with weight wt.
inline void sf_cssm_trilinear(__global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
                              int W, int H, float u, float v, float f, int nch, float wt, float* acc) {
  float t;
  const int k0 = sf_lod(f, sf_mip_top(W, H), &t);
  float a[SF_CHANNELS];
  sf_cssm_level(basis, chain, W, H, k0, u, v, nch, a);
  if (t > 0.0f) {
    float b[SF_CHANNELS];
    sf_cssm_level(basis, chain, W, H, k0 + 1, u, v, nch, b);
    for (int c = 0; c < nch; ++c) a[c] = mix(a[c], b[c], t);
  }
  for (int c = 0; c < nch; ++c) acc[c] = fma(wt, a[c], acc[c]);
}
#endif

// Mean of the first nch planes over fx x fy texels (each >= 1) centred at (u, v).
inline void sf_cssm_lookup(__global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
                           __global const float* restrict pk, int W, int H, float u, float v, float fx, float fy,
                           int nch, float* out) {
#if SF_LOOKUP == SF_LOOKUP_MIPS
  const float lo = fmin(fx, fy), hi = fmax(fx, fy);
  const int n = clamp((int)ceil(hi / lo - 0.01f), 1, SF_CSSM_MAX_PROBES);
  const float step = hi / (float)n;
  const float f = SF_CSSM_MIP_SCALE * fmax(lo, step);
  for (int c = 0; c < nch; ++c) out[c] = 0.0f;
  for (int j = 0; j < n; ++j) {
    const float off = ((float)j + 0.5f - 0.5f * (float)n) * step;  // texels along the long side
    const float pu = fx >= fy ? u + off / (float)W : u, pv = fx >= fy ? v : v + off / (float)H;
    sf_cssm_trilinear(basis, chain, W, H, pu, pv, f, nch, 1.0f / (float)n, out);
  }
  for (int c = 0; c < nch; ++c) out[c] = SF_CSSM_DECODE(out[c]);
#else
  const float sx = 0.5f * (isfinite(fx) ? fmax(fx, 1.0f) : 1.0f), sy = 0.5f * (isfinite(fy) ? fmax(fy, 1.0f) : 1.0f);
  const float X0 = fma(u, (float)W, -sx), X1 = fma(u, (float)W, sx);
  const float Y0 = fma(v, (float)H, -sy), Y1 = fma(v, (float)H, sy);
  const float area = (X1 - X0) * (Y1 - Y0);
  for (int c = 0; c < nch; ++c) {
    const float2 a = sf_dd_sum(sf_cssm_sat_at(pk, W, H, X1, Y1, c), -sf_cssm_sat_at(pk, W, H, X0, Y1, c));
    const float2 b = sf_dd_sum(sf_cssm_sat_at(pk, W, H, X1, Y0, c), -sf_cssm_sat_at(pk, W, H, X0, Y0, c));
    const float2 sum = sf_dd_sum(a, -b);
    out[c] = (sum.x + sum.y) / area;
  }
#endif
}

// sat.cl's table (plane c: hi at 2 c P, lo at (2 c + 1) P, common.clh's pitch) interleaved per
// entry e = y (W + 1) + x: packed[2 (e C + c) + {0, 1}] = (hi, lo) of S[y][x].
__kernel void sf_cssm_sat_pack(__global const float* restrict sat, __global float* restrict packed,
                               const int W, const int H) {
  const int e = get_global_id(0);
  if (e >= (W + 1) * (H + 1)) return;
  const size_t Wp = sf_sat_pitch(W), P = Wp * (H + 1);
  const size_t s = (size_t)(e / (W + 1)) * Wp + SF_SAT_X0 + e % (W + 1);
  for (int c = 0; c < SF_CHANNELS; ++c) {
    packed[2 * ((size_t)e * SF_CHANNELS + c)] = sat[2 * c * P + s];
    packed[2 * ((size_t)e * SF_CHANNELS + c) + 1] = sat[(2 * c + 1) * P + s];
  }
}

// sf_cssm_params: shared_types.clh.

__kernel void sf_cssm_basis(__global const float* restrict depth, __global sf_stored* restrict basis,
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
    sf_store(basis, k * P + i, SF_CSSM_ENCODE(s));
    sf_store(basis, (SF_M + k) * P + i, SF_CSSM_ENCODE(c));
    sf_store(basis, (2 * SF_M + k) * P + i, SF_CSSM_ENCODE(z * s));
    sf_store(basis, (3 * SF_M + k) * P + i, SF_CSSM_ENCODE(z * c));
    const float sn = fma(s, c2, c * s2);
    c = fma(c, c2, -s * s2);
    s = sn;
  }
  sf_store(basis, 4 * SF_M * P + i, SF_CSSM_ENCODE(0.5f * z));
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

__kernel void sf_cssm_points(__global const sf_stored* restrict basis, const int W, const int H,
                             __global const sf_stored* restrict chain, __global const float* restrict packed,
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
  const float2 fp = sf_soft_footprint(f, count, i);
  float b[SF_CHANNELS];
  const float2 search = sf_soft_texels(L, sf_soft_width(L, dd, 0.0f), W, H, fp);
  sf_cssm_lookup(basis, chain, packed, W, H, ui, vi, search.x, search.y, SF_CHANNELS, b);
  float num;
  // Stage 1 at d - z_offset (0.5 / M): there a lit texel (z = d) gives 1 - f ~ -0.09, close to
  // 0; at the visibility offset it would count as a quarter blocker at depth d.
  const float den = 1.0f - sf_cssm_series(b, dd - P.z_offset, &num);
  const bool blocked = den >= P.min_den;  // false also for NaN
  if (!blocked && !P.contact) {
    out[i] = 1.0f;
    if (zavg_out) zavg_out[i] = NAN;
    return;
  }
  // No blocker farther than z_offset: any blocker is in contact (z_avg = d), so stage 2 reads
  // the receiver's own footprint, where the visibility offset still finds close blockers.
  const float zavg = blocked ? clamp(num / den, 0.0f, dd) : dd;
  if (zavg_out) zavg_out[i] = blocked ? zavg : NAN;
  const float2 fw = sf_soft_texels(L, P.width_scale * sf_soft_width(L, dd, zavg), W, H, fp);
  sf_cssm_lookup(basis, chain, packed, W, H, ui, vi, fw.x, fw.y, 2 * SF_M, b);
  float vis = clamp(fma(P.scale, fma(sf_cssm_series(b, dp, 0), P.inv_lit, -0.5f), 0.5f), 0.0f, 1.0f);
  if (P.sharpen_a > 0.0f) vis = pow(vis, 1.0f + P.sharpen_a * exp(-P.sharpen_b * (dd - zavg)));
  out[i] = vis;
}
