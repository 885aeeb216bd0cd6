// Summed-area tables of planar N-channel images, accumulated in float-float ("double-float":
// a value is hi + lo, two floats, about 48 significant bits) so that the table keeps its
// precision at 4096x4096 (docs/lookups.md has the measured bound).
// Needs common.clh, storage.clh and vecio.clh before it.
//
// Layout (float): channel c has two planes of (W+1) x (H+1), row pitch W+1: hi at 2c P, lo at
// (2c+1) P with P = (W+1)(H+1). S[y][x] = sum of texels [0, x) x [0, y) (row 0 and column 0
// are zero), so the area-weighted sum over any box is a bilinear interpolation of S at its
// corners (lookup.clh, sf_lookup_box).
//
// Two launches:
// - sf_sat_bands: column sums of each band of rows (float-float), one work-item per 16
//   columns x band x channel.
// - sf_sat_rows: one work-item per band x channel. Its first S row comes from the bands above
//   (column carries, prefix along the row in float-float); then each input row y adds its row
//   prefix to S row y: S[y+1][x+1] = S[y][x+1] + T + p(x), where p is the inclusive prefix
//   within a 16-texel vector (log-step) and T the running total of the vectors before it, all
//   in float-float: every entry is the exact sum to about 2^-44 of its magnitude.

#define SF_DD_DEFINE(T, S)                                                           \
  inline void sf_two_sum##S(T a, T b, T* s, T* e) {                                 \
    *s = a + b;                                                                     \
    const T bb = *s - a;                                                            \
    *e = (a - (*s - bb)) + (b - bb);                                                \
  }                                                                                 \
  /* (hi, lo) += (bhi, blo) */                                                      \
  inline void sf_dd_add##S(T* hi, T* lo, T bhi, T blo) {                            \
    T s, e;                                                                         \
    sf_two_sum##S(*hi, bhi, &s, &e);                                                \
    e += *lo + blo;                                                                 \
    *hi = s + e;                                                                    \
    *lo = e - (*hi - s);                                                            \
  }
SF_DD_DEFINE(float, )
SF_DD_DEFINE(float16, 16)

// 16 texels of a stored plane row from x (zeros from W on).
inline float16 sf_sat_load_stored(__global const sf_stored* row, int x, int W) {
  if (x + 16 <= W) return SF_VLOAD(16, row, x);
  float t[16];
  for (int i = 0; i < 16; ++i) t[i] = x + i < W ? sf_load(row, x + i) : 0.0f;
  return vload16(0, t);
}
// 16 floats from p[x] on, elements from n on read as 0.
inline float16 sf_sat_load(__global const float* p, int x, int n) {
  if (x + 16 <= n) return *(__global const sf_float16u*)(p + x);
  float t[16];
  for (int i = 0; i < 16; ++i) t[i] = x + i < n ? p[x + i] : 0.0f;
  return vload16(0, t);
}
inline void sf_sat_put(__global float* p, int x, int n, float16 v) {
  if (x + 16 <= n) {
    *(__global sf_float16u*)(p + x) = v;
    return;
  }
  float t[16];
  vstore16(v, 0, t);
  for (int i = 0; i < 16 && x + i < n; ++i) p[x + i] = t[i];
}

// Inclusive prefix sum within a vector in float-float (Hillis-Steele: 4 shifted additions).
#define SF_SHIFT(x, m) shuffle2((x), z, (uint16)m)
#define SF_PREFIX_STEP(m)                                \
  {                                                      \
    const float16 sh = SF_SHIFT(*hi, m), sl = SF_SHIFT(*lo, m); \
    sf_dd_add16(hi, lo, sh, sl);                         \
  }
inline void sf_prefix16(float16 v, float16* hi, float16* lo) {
  const float16 z = (float16)(0.0f);
  *hi = v;
  *lo = z;
  SF_PREFIX_STEP((16, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14))
  SF_PREFIX_STEP((16, 16, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13))
  SF_PREFIX_STEP((16, 16, 16, 16, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11))
  SF_PREFIX_STEP((16, 16, 16, 16, 16, 16, 16, 16, 0, 1, 2, 3, 4, 5, 6, 7))
}

// Band sums: bands (float) holds, for channel c and band b, the hi row at ((c nb + b) 2) W and
// the lo row right after it. NDRange (ceil(W / 16), nb, N), local (1, 1, 1).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_bands(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global float* restrict bands) {
  const int x = get_global_id(0) * 16, b = get_global_id(1), c = get_global_id(2);
  if (x >= W) return;
  __global const sf_stored* plane = src + (size_t)c * W * H;
  const int y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  float16 hi = 0.0f, lo = 0.0f;
  for (int y = y0; y < y1; ++y) sf_dd_add16(&hi, &lo, sf_sat_load_stored(plane + (size_t)y * W, x, W), 0.0f);
  __global float* out = bands + (size_t)(c * nb + b) * 2 * W;
  sf_sat_put(out, x, W, hi);
  sf_sat_put(out + W, x, W, lo);
}

// NDRange (nb, N), local (1, 1): see the file comment.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_rows(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global const float* restrict bands, __global float* restrict sat) {
  const int b = get_global_id(0), c = get_global_id(1);
  const int y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  const int Wp = W + 1;
  const size_t P = (size_t)Wp * (H + 1);
  __global float* shi = sat + 2 * c * P;
  __global float* slo = shi + P;
  __global const sf_stored* plane = src + (size_t)c * W * H;
  __global const float* cb = bands + (size_t)c * nb * 2 * W;

  // S row y0: prefix along x of the column carries sum_{b' < b} bands(b').
  {
    float thi = 0.0f, tlo = 0.0f;
    __global float* rh = shi + (size_t)y0 * Wp;
    __global float* rl = slo + (size_t)y0 * Wp;
    rh[0] = 0.0f;
    rl[0] = 0.0f;
    for (int x = 0; x < W; x += 16) {
      float16 chi = 0.0f, clo = 0.0f;
      for (int k = 0; k < b; ++k)
        sf_dd_add16(&chi, &clo, sf_sat_load(cb + (size_t)k * 2 * W, x, W),
                    sf_sat_load(cb + (size_t)k * 2 * W + W, x, W));
      float h[16], l[16];
      vstore16(chi, 0, h);
      vstore16(clo, 0, l);
      for (int i = 0; i < 16 && x + i < W; ++i) {
        sf_dd_add(&thi, &tlo, h[i], l[i]);
        h[i] = thi;
        l[i] = tlo;
      }
      sf_sat_put(rh + 1, x, W, vload16(0, h));
      sf_sat_put(rl + 1, x, W, vload16(0, l));
    }
  }
  // Rows: input row y -> S row y + 1. The band owns S rows y0 .. y1 - 1, the last band row H too.
  const int y_end = b == nb - 1 ? y1 : y1 - 1;
  for (int y = y0; y < y_end; ++y) {
    __global const sf_stored* in = plane + (size_t)y * W;
    __global const float* ph = shi + (size_t)y * Wp + 1;
    __global const float* pl = slo + (size_t)y * Wp + 1;
    __global float* oh = shi + (size_t)(y + 1) * Wp;
    __global float* ol = slo + (size_t)(y + 1) * Wp;
    oh[0] = 0.0f;
    ol[0] = 0.0f;
    float thi = 0.0f, tlo = 0.0f;
    for (int x = 0; x < W; x += 16) {
      float16 phi, plo;
      sf_prefix16(sf_sat_load_stored(in, x, W), &phi, &plo);
      const float last_hi = phi.sf, last_lo = plo.sf;  // the vector's total
      sf_dd_add16(&phi, &plo, (float16)(thi), (float16)(tlo));  // r = T + p per lane
      float16 shi_v = sf_sat_load(ph, x, W), slo_v = sf_sat_load(pl, x, W);
      sf_dd_add16(&shi_v, &slo_v, phi, plo);
      sf_sat_put(oh + 1, x, W, shi_v);
      sf_sat_put(ol + 1, x, W, slo_v);
      sf_dd_add(&thi, &tlo, last_hi, last_lo);
    }
  }
}
