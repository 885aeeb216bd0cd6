// Summed-area tables of planar N-channel images, accumulated in double (or float-float where the
// device has no doubles: sat_accum.clh) and stored as float-float ("double-float": a value is
// hi + lo, two floats) so that the table keeps its precision at 4096x4096 (docs/lookups.md has
// the measured bound).
// Needs common.clh, storage.clh, vecio.clh and sat_accum.clh before it.
//
// Layout (float): channel c has two planes of (W+1) x (H+1), row pitch W+1: hi at 2c P, lo at
// (2c+1) P with P = (W+1)(H+1). S[y][x] = sum of texels [0, x) x [0, y) (row 0 and column 0
// are zero), so the area-weighted sum over any box is a bilinear interpolation of S at its
// corners (lookup.clh, sf_lookup_box). Every entry is the double sum split into hi = the
// nearest float and lo = the nearest float to the (exact) remainder: |hi + lo - S| <= 2^-48 |S|
// plus the double rounding of the sum, <= (x + y + band_rows) 2^-53 sum|texels| (worst case;
// the float-float accumulator: about 2^-44 |S|).
//
// Two launches:
// - sf_sat_bands: column sums of each band of rows (accumulator), one work-item per
//   SF_SAT_STRIP columns x band x channel walking the band's rows in order.
// - sf_sat_rows: one work-item per band x channel. Its first S row comes from the bands above
//   (column carries, prefix along the row). The band's rows then go in blocks of 8 rows x 8
//   columns, left to right: the block is transposed in registers so that the row prefix
//   becomes 8 sequential sf_acc8 additions with one row per vector lane (a running total per
//   row carried from block to block), transposed back, and S[y+1] = S[y] + row prefix added
//   down the block's columns from the unrounded S row above the block (an accumulator row per
//   band in the scratch, still in cache).
// Traffic: the image is read twice (bands, rows) and the table written once. The previous
// float-float accumulator is bound by the latency of its running sum (a chain of ~8 dependent
// float additions per column step): a double addition is one.

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
#define SF_UNPACKLO(T, a, b) (T)((a).s0, (b).s0, (a).s1, (b).s1, (a).s4, (b).s4, (a).s5, (b).s5)
#define SF_UNPACKHI(T, a, b) (T)((a).s2, (b).s2, (a).s3, (b).s3, (a).s6, (b).s6, (a).s7, (b).s7)
#define SF_SHUFLO(T, a, b) (T)((a).s0, (a).s1, (b).s0, (b).s1, (a).s4, (a).s5, (b).s4, (b).s5)
#define SF_SHUFHI(T, a, b) (T)((a).s2, (a).s3, (b).s2, (b).s3, (a).s6, (a).s7, (b).s6, (b).s7)
#define SF_PERMLO(T, a, b) (T)((a).lo, (b).lo)
#define SF_PERMHI(T, a, b) (T)((a).hi, (b).hi)
// T: float8 or double8 (the accumulator's transpose, sat_accum.clh).
#define SF_TRANSPOSE8(T, r0, r1, r2, r3, r4, r5, r6, r7)                               \
  {                                                                                     \
    const T t0 = SF_UNPACKLO(T, r0, r1), t1 = SF_UNPACKHI(T, r0, r1);                   \
    const T t2 = SF_UNPACKLO(T, r2, r3), t3 = SF_UNPACKHI(T, r2, r3);                   \
    const T t4 = SF_UNPACKLO(T, r4, r5), t5 = SF_UNPACKHI(T, r4, r5);                   \
    const T t6 = SF_UNPACKLO(T, r6, r7), t7 = SF_UNPACKHI(T, r6, r7);                   \
    const T s0 = SF_SHUFLO(T, t0, t2), s1 = SF_SHUFHI(T, t0, t2);                       \
    const T s2 = SF_SHUFLO(T, t1, t3), s3 = SF_SHUFHI(T, t1, t3);                       \
    const T s4 = SF_SHUFLO(T, t4, t6), s5 = SF_SHUFHI(T, t4, t6);                       \
    const T s6 = SF_SHUFLO(T, t5, t7), s7 = SF_SHUFHI(T, t5, t7);                       \
    r0 = SF_PERMLO(T, s0, s4);                                                          \
    r1 = SF_PERMLO(T, s1, s5);                                                          \
    r2 = SF_PERMLO(T, s2, s6);                                                          \
    r3 = SF_PERMLO(T, s3, s7);                                                          \
    r4 = SF_PERMHI(T, s0, s4);                                                          \
    r5 = SF_PERMHI(T, s1, s5);                                                          \
    r6 = SF_PERMHI(T, s2, s6);                                                          \
    r7 = SF_PERMHI(T, s3, s7);                                                          \
  }

#ifndef SF_SAT_STRIP
#define SF_SAT_STRIP 256
#endif

// Band sums: scratch (sf_acc) holds, for channel c and band b, the column sums of the band's
// rows at (c nb + b) W. One work-item per SF_SAT_STRIP columns x band x channel walks the
// band's rows in order (contiguous reads), its column sums in the output row (in L1).
// NDRange (ceil(W / SF_SAT_STRIP), nb, N), local (1, 1, 1).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_bands(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global sf_acc* restrict scratch) {
  const int xs = get_global_id(0) * SF_SAT_STRIP, b = get_global_id(1), c = get_global_id(2);
  const int xe = min(W, xs + SF_SAT_STRIP);
  __global const sf_stored* plane = src + (size_t)c * W * H;
  const int y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  __global sf_acc* o = scratch + (size_t)(c * nb + b) * W;
  for (int x = xs; x < xe; x += 16)
    sf_acc16_put(o, x, xe, sf_acc16_of(sf_sat_load_stored(plane + (size_t)y0 * W, x, W)));
  for (int y = y0 + 1; y < y1; ++y) {
    __global const sf_stored* row = plane + (size_t)y * W;
    if (xe - xs == SF_SAT_STRIP) {
      for (int x = xs; x < xe; x += 16)
        sf_acc16_vstore(o + x, sf_acc16_addf(sf_acc16_vload(o + x), SF_VLOAD(16, row, x)));
    } else {
      for (int x = xs; x < xe; x += 16)
        sf_acc16_put(o, x, xe, sf_acc16_addf(sf_acc16_load(o, x, xe), sf_sat_load_stored(row, x, W)));
    }
  }
}

// NDRange (nb, N), local (1, 1): see the file comment. scratch: the band sums (N nb W entries)
// then one row of W entries per band and channel (the band's last S row, unrounded).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_rows(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global sf_acc* restrict scratch, __global float* restrict sat) {
  const int b = get_global_id(0), c = get_global_id(1);
  const int y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  const int Wp = W + 1, N = get_global_size(1);
  const size_t P = (size_t)Wp * (H + 1);
  __global float* shi = sat + 2 * c * P;
  __global float* slo = shi + P;
  __global const sf_stored* plane = src + (size_t)c * W * H;
  __global const sf_acc* cb = scratch + (size_t)c * nb * W;
  __global sf_acc* vrow = scratch + (size_t)(N + c) * nb * W + (size_t)b * W;

  // S row y0: prefix along x of the column carries sum_{b' < b} bands(b').
  {
    sf_acc t = SF_ACC_ZERO;
    __global float* rh = shi + (size_t)y0 * Wp;
    __global float* rl = slo + (size_t)y0 * Wp;
    rh[0] = 0.0f;
    rl[0] = 0.0f;
    for (int x = 0; x < W; x += 8) {
      sf_acc8 cs = sf_acc8_zero();
      for (int k = 0; k < b; ++k) cs = sf_acc8_add(cs, sf_acc8_load(cb + (size_t)k * W, x, W));
      sf_acc d[8];
      sf_acc8_to_array(cs, d);
      for (int i = 0; i < 8; ++i) {
        t = sf_acc_add(t, d[i]);
        d[i] = t;
      }
      const sf_acc8 s = sf_acc8_of_array(d);
      sf_acc8_put(vrow, x, W, s);
      float8 h, l;
      sf_acc8_split(s, &h, &l);
      sf_sat_put8(rh + 1, x, W, h);
      sf_sat_put8(rl + 1, x, W, l);
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
    sf_acc8 t = sf_acc8_zero();  // running row totals, lane i = row ys + i
    __global const sf_stored* in = plane + (size_t)ys * W;
    __global float* oh = shi + (size_t)(ys + 1) * Wp + 1;
    __global float* ol = slo + (size_t)(ys + 1) * Wp + 1;
    for (int x = 0; x < W; x += 8) {
      const bool full = nr == 8 && x + 8 <= W;
      float8 r0, r1, r2, r3, r4, r5, r6, r7;
      if (full) {
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
      SF_TRANSPOSE8(float8, r0, r1, r2, r3, r4, r5, r6, r7)  // r_j = column x + j, lane i = row ys + i
      sf_acc8 h0, h1, h2, h3, h4, h5, h6, h7;
#define SF_STEP(j) t = sf_acc8_addf(t, r##j); h##j = t;
      SF_STEP(0) SF_STEP(1) SF_STEP(2) SF_STEP(3) SF_STEP(4) SF_STEP(5) SF_STEP(6) SF_STEP(7)
#undef SF_STEP
      SF_ACC_TRANSPOSE8(h0, h1, h2, h3, h4, h5, h6, h7)  // h_i = row ys + i's prefix, columns x..
      // Rows past nr are zero (their prefixes too): v ends as S row ys + nr.
      sf_acc8 v = sf_acc8_load(vrow, x, W);
      float8 fh, fl;
      if (full) {
#define SF_OUT(i)                                                 \
  v = sf_acc8_add(v, h##i);                                       \
  sf_acc8_split(v, &fh, &fl);                                     \
  *(__global sf_float8u*)(oh + (size_t)(i) * Wp + x) = fh;        \
  *(__global sf_float8u*)(ol + (size_t)(i) * Wp + x) = fl;
        SF_OUT(0) SF_OUT(1) SF_OUT(2) SF_OUT(3) SF_OUT(4) SF_OUT(5) SF_OUT(6) SF_OUT(7)
#undef SF_OUT
        sf_acc8_vstore(vrow + x, v);
      } else {
        const sf_acc8 ph[8] = {h0, h1, h2, h3, h4, h5, h6, h7};
        for (int i = 0; i < nr; ++i) {
          v = sf_acc8_add(v, ph[i]);
          sf_acc8_split(v, &fh, &fl);
          sf_sat_put8(oh + (size_t)i * Wp, x, W, fh);
          sf_sat_put8(ol + (size_t)i * Wp, x, W, fl);
        }
        sf_acc8_put(vrow, x, W, v);
      }
    }
  }
}
