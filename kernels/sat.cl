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
// - sf_sat_bands: column sums of each band of rows (float-float), one work-item per
//   SF_SAT_STRIP columns x band x channel walking the band's rows in order.
// - sf_sat_rows: one work-item per band x channel. Its first S row comes from the bands above
//   (column carries, prefix along the row in float-float). The band's rows then go in blocks
//   of 8 rows x 8 columns, left to right: the block is transposed in registers so that the
//   row prefix becomes 8 sequential float-float additions with one row per vector lane (a
//   running total per row carried from block to block), transposed back (hi and lo), and
//   S[y+1] = S[y] + row prefix added down the block's columns from the S row above the block
//   (written by the same work-item one block row earlier, still in cache). Every entry is the
//   exact sum to about 2^-44 of its magnitude: no partial sum is ever rounded to float.
// Traffic: the image is read twice (bands, rows) and the table written once; the old row-vector
// version (a log-step prefix of 16 texels in float-float) spent ~4x the arithmetic per texel.

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
  }                                                                                 \
  /* (hi, lo) += b */                                                               \
  inline void sf_dd_add1##S(T* hi, T* lo, T b) {                                    \
    T s, e;                                                                         \
    sf_two_sum##S(*hi, b, &s, &e);                                                  \
    e += *lo;                                                                       \
    *hi = s + e;                                                                    \
    *lo = e - (*hi - s);                                                            \
  }
SF_DD_DEFINE(float, )
SF_DD_DEFINE(float8, 8)
SF_DD_DEFINE(float16, 16)

// 16 texels of a stored plane row from x (zeros from W on).
inline float16 sf_sat_load_stored(__global const sf_stored* row, int x, int W) {
  if (x + 16 <= W) return SF_VLOAD(16, row, x);
  float t[16];
  for (int i = 0; i < 16; ++i) t[i] = x + i < W ? sf_load(row, x + i) : 0.0f;
  return vload16(0, t);
}
inline float8 sf_sat_load_stored8(__global const sf_stored* row, int x, int W) {
  if (x + 8 <= W) return SF_VLOAD(8, row, x);
  float t[8];
  for (int i = 0; i < 8; ++i) t[i] = x + i < W ? sf_load(row, x + i) : 0.0f;
  return vload8(0, t);
}
// 16 floats from p[x] on, elements from n on read as 0.
inline float16 sf_sat_load(__global const float* p, int x, int n) {
  if (x + 16 <= n) return *(__global const sf_float16u*)(p + x);
  float t[16];
  for (int i = 0; i < 16; ++i) t[i] = x + i < n ? p[x + i] : 0.0f;
  return vload16(0, t);
}
inline float8 sf_sat_load8(__global const float* p, int x, int n) {
  if (x + 8 <= n) return *(__global const sf_float8u*)(p + x);
  float t[8];
  for (int i = 0; i < 8; ++i) t[i] = x + i < n ? p[x + i] : 0.0f;
  return vload8(0, t);
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
inline void sf_sat_put8(__global float* p, int x, int n, float8 v) {
  if (x + 8 <= n) {
    *(__global sf_float8u*)(p + x) = v;
    return;
  }
  float t[8];
  vstore8(v, 0, t);
  for (int i = 0; i < 8 && x + i < n; ++i) p[x + i] = t[i];
}

// In-register 8x8 transpose (unpack, 4-lane shuffle, 128-bit lane permute: 24 shuffles).
#define SF_UNPACKLO(a, b) (float8)((a).s0, (b).s0, (a).s1, (b).s1, (a).s4, (b).s4, (a).s5, (b).s5)
#define SF_UNPACKHI(a, b) (float8)((a).s2, (b).s2, (a).s3, (b).s3, (a).s6, (b).s6, (a).s7, (b).s7)
#define SF_SHUFLO(a, b) (float8)((a).s0, (a).s1, (b).s0, (b).s1, (a).s4, (a).s5, (b).s4, (b).s5)
#define SF_SHUFHI(a, b) (float8)((a).s2, (a).s3, (b).s2, (b).s3, (a).s6, (a).s7, (b).s6, (b).s7)
#define SF_PERMLO(a, b) (float8)((a).lo, (b).lo)
#define SF_PERMHI(a, b) (float8)((a).hi, (b).hi)
#define SF_TRANSPOSE8(r0, r1, r2, r3, r4, r5, r6, r7)                                  \
  {                                                                                     \
    const float8 t0 = SF_UNPACKLO(r0, r1), t1 = SF_UNPACKHI(r0, r1);                    \
    const float8 t2 = SF_UNPACKLO(r2, r3), t3 = SF_UNPACKHI(r2, r3);                    \
    const float8 t4 = SF_UNPACKLO(r4, r5), t5 = SF_UNPACKHI(r4, r5);                    \
    const float8 t6 = SF_UNPACKLO(r6, r7), t7 = SF_UNPACKHI(r6, r7);                    \
    const float8 s0 = SF_SHUFLO(t0, t2), s1 = SF_SHUFHI(t0, t2);                        \
    const float8 s2 = SF_SHUFLO(t1, t3), s3 = SF_SHUFHI(t1, t3);                        \
    const float8 s4 = SF_SHUFLO(t4, t6), s5 = SF_SHUFHI(t4, t6);                        \
    const float8 s6 = SF_SHUFLO(t5, t7), s7 = SF_SHUFHI(t5, t7);                        \
    r0 = SF_PERMLO(s0, s4);                                                             \
    r1 = SF_PERMLO(s1, s5);                                                             \
    r2 = SF_PERMLO(s2, s6);                                                             \
    r3 = SF_PERMLO(s3, s7);                                                             \
    r4 = SF_PERMHI(s0, s4);                                                             \
    r5 = SF_PERMHI(s1, s5);                                                             \
    r6 = SF_PERMHI(s2, s6);                                                             \
    r7 = SF_PERMHI(s3, s7);                                                             \
  }

#ifndef SF_SAT_STRIP
#define SF_SAT_STRIP 256
#endif

// Band sums: bands (float) holds, for channel c and band b, the hi row at ((c nb + b) 2) W and
// the lo row right after it. One work-item per SF_SAT_STRIP columns x band x channel walks the
// band's rows in order (contiguous reads), its column sums in the output rows (in L1).
// NDRange (ceil(W / SF_SAT_STRIP), nb, N), local (1, 1, 1).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_bands(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global float* restrict bands) {
  const int xs = get_global_id(0) * SF_SAT_STRIP, b = get_global_id(1), c = get_global_id(2);
  const int xe = min(W, xs + SF_SAT_STRIP);
  __global const sf_stored* plane = src + (size_t)c * W * H;
  const int y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  __global float* oh = bands + (size_t)(c * nb + b) * 2 * W;
  __global float* ol = oh + W;
  for (int x = xs; x < xe; x += 16) {
    sf_sat_put(oh, x, xe, sf_sat_load_stored(plane + (size_t)y0 * W, x, W));
    sf_sat_put(ol, x, xe, (float16)(0.0f));
  }
  for (int y = y0 + 1; y < y1; ++y) {
    __global const sf_stored* row = plane + (size_t)y * W;
    if (xe - xs == SF_SAT_STRIP) {
      for (int x = xs; x < xe; x += 16) {
        float16 hi = *(__global sf_float16u*)(oh + x), lo = *(__global sf_float16u*)(ol + x);
        sf_dd_add116(&hi, &lo, SF_VLOAD(16, row, x));
        *(__global sf_float16u*)(oh + x) = hi;
        *(__global sf_float16u*)(ol + x) = lo;
      }
    } else {
      for (int x = xs; x < xe; x += 16) {
        float16 hi = sf_sat_load(oh, x, xe), lo = sf_sat_load(ol, x, xe);
        sf_dd_add116(&hi, &lo, sf_sat_load_stored(row, x, W));
        sf_sat_put(oh, x, xe, hi);
        sf_sat_put(ol, x, xe, lo);
      }
    }
  }
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
  // Input rows ys .. ys + 7 -> S rows ys + 1 .. ys + 8. The band owns S rows y0 .. y1 - 1
  // (the last band row H too): row y1 is the next band's first row.
  const int y_end = b == nb - 1 ? y1 : y1 - 1;
  for (int ys = y0; ys < y_end; ys += 8) {
    const int nr = min(8, y_end - ys);
    for (int i = 0; i < nr; ++i) {
      shi[(size_t)(ys + 1 + i) * Wp] = 0.0f;
      slo[(size_t)(ys + 1 + i) * Wp] = 0.0f;
    }
    float8 thi = 0.0f, tlo = 0.0f;  // running row totals, lane i = row ys + i
    __global const float* ah = shi + (size_t)ys * Wp + 1;
    __global const float* al = slo + (size_t)ys * Wp + 1;
    __global const sf_stored* in = plane + (size_t)ys * W;
    for (int x = 0; x < W; x += 8) {
      float8 r0, r1, r2, r3, r4, r5, r6, r7;
      if (nr == 8 && x + 8 <= W) {
        r0 = SF_VLOAD(8, in, x);
        r1 = SF_VLOAD(8, in + W, x);
        r2 = SF_VLOAD(8, in + 2 * W, x);
        r3 = SF_VLOAD(8, in + 3 * W, x);
        r4 = SF_VLOAD(8, in + 4 * W, x);
        r5 = SF_VLOAD(8, in + 5 * W, x);
        r6 = SF_VLOAD(8, in + 6 * W, x);
        r7 = SF_VLOAD(8, in + 7 * W, x);
      } else {
        const float8 z = 0.0f;
        r0 = sf_sat_load_stored8(in, x, W);
        r1 = nr > 1 ? sf_sat_load_stored8(in + W, x, W) : z;
        r2 = nr > 2 ? sf_sat_load_stored8(in + 2 * W, x, W) : z;
        r3 = nr > 3 ? sf_sat_load_stored8(in + 3 * W, x, W) : z;
        r4 = nr > 4 ? sf_sat_load_stored8(in + 4 * W, x, W) : z;
        r5 = nr > 5 ? sf_sat_load_stored8(in + 5 * W, x, W) : z;
        r6 = nr > 6 ? sf_sat_load_stored8(in + 6 * W, x, W) : z;
        r7 = nr > 7 ? sf_sat_load_stored8(in + 7 * W, x, W) : z;
      }
      SF_TRANSPOSE8(r0, r1, r2, r3, r4, r5, r6, r7)  // r_j = column x + j, lane i = row ys + i
      float8 h0, h1, h2, h3, h4, h5, h6, h7, l0, l1, l2, l3, l4, l5, l6, l7;
#define SF_STEP(j) sf_dd_add18(&thi, &tlo, r##j); h##j = thi; l##j = tlo;
      SF_STEP(0) SF_STEP(1) SF_STEP(2) SF_STEP(3) SF_STEP(4) SF_STEP(5) SF_STEP(6) SF_STEP(7)
#undef SF_STEP
      SF_TRANSPOSE8(h0, h1, h2, h3, h4, h5, h6, h7)  // h_i + l_i = row ys + i's prefix, columns x..
      SF_TRANSPOSE8(l0, l1, l2, l3, l4, l5, l6, l7)
      float8 vh = sf_sat_load8(ah, x, W), vl = sf_sat_load8(al, x, W);
      __global float* oh = shi + (size_t)(ys + 1) * Wp + 1;
      __global float* ol = slo + (size_t)(ys + 1) * Wp + 1;
      if (nr == 8 && x + 8 <= W) {
#define SF_OUT(i)                                                 \
  sf_dd_add8(&vh, &vl, h##i, l##i);                               \
  *(__global sf_float8u*)(oh + (size_t)(i) * Wp + x) = vh;        \
  *(__global sf_float8u*)(ol + (size_t)(i) * Wp + x) = vl;
        SF_OUT(0) SF_OUT(1) SF_OUT(2) SF_OUT(3) SF_OUT(4) SF_OUT(5) SF_OUT(6) SF_OUT(7)
#undef SF_OUT
      } else {
        const float8 ph[8] = {h0, h1, h2, h3, h4, h5, h6, h7}, pl[8] = {l0, l1, l2, l3, l4, l5, l6, l7};
        for (int i = 0; i < nr; ++i) {
          sf_dd_add8(&vh, &vl, ph[i], pl[i]);
          sf_sat_put8(oh + (size_t)i * Wp, x, W, vh);
          sf_sat_put8(ol + (size_t)i * Wp, x, W, vl);
        }
      }
    }
  }
}
