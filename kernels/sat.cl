// Summed-area tables of planar N-channel images, accumulated in double (or float-float where the
// device has no doubles: sat_accum.clh) and stored as float-float ("double-float": a value is
// hi + lo, two floats) so that the table keeps its precision at 4096x4096 (docs/lookups.md has
// the measured bound).
// Needs common.clh, storage.clh, vecio.clh and sat_accum.clh before it.
//
// Layout (float): channel c has two planes of H+1 rows of pitch Wp = sf_sat_pitch(W) (common.clh),
// hi at 2c P, lo at (2c+1) P with P = Wp (H+1); S[y][x] is at y Wp + SF_SAT_X0 + x in its plane.
// S[y][x] = sum of texels [0, x) x [0, y) (row 0 and column 0 are zero), so the area-weighted
// sum over any box is a bilinear interpolation of S at its corners (lookup.clh, sf_lookup_box).
// Every entry is the double sum split into hi = the sum truncated to 24 significant bits (a
// float) and lo = the nearest float to the (exact) remainder: |hi + lo - S| <= 2^-47 |S| plus the
// double rounding of the sum, <= (x + y + band_rows) 2^-53 sum|texels| (worst case; the
// float-float accumulator: about 2^-44 |S|).
//
// A band of rows (sf_sat_band) starts from its column carries, the column sums of every row above
// it: its first S row is their prefix along the row. Its rows then go in blocks of 8 rows x 8
// columns, left to right: the block is transposed in registers so that the row prefix becomes 8
// sequential sf_acc8 additions with one row per vector lane (a running total per row carried
// from block to block), transposed back, and S[y+1] = S[y] + row prefix added down the block's
// columns from the unrounded S row above the block (an accumulator row per band in the scratch,
// still in cache). Two such blocks side by side make 16 entries per row, one whole 64-byte line
// of the table, streamed past the caches (sf_stream16, vecio.clh).
// Three schedules (enqueue_sat, SatSchedule):
// - sf_sat_rows alone, one band per channel: no carries; the image read once.
// - sf_sat_chain (CPUs), one launch: each band sums its own columns, takes its carries from the
//   bands above as they publish them (a look-back that never waits), publishes its own and builds
//   its rows, reading its rows the second time from cache. Work-groups pass the carries through
//   memory published with atomics, which OpenCL 1.2 does not order across work-groups in general
//   (Oclgrind's race detector reports the carries): sound on CPU devices (one coherent address
//   space; the seq_cst atomics order the plain accesses around them), not assumed elsewhere.
// - sf_sat_bands then sf_sat_rows: every band's column sums, then the bands' rows; the image is
//   read twice.
// The float-float accumulator is bound by the latency of its running sum (a chain of ~8
// dependent float additions per column step): a double addition is one.

// The Gpu family (SF_SAT_GPU, SatSchedule::WorkGroupScan; docs/gpu.md, "Launch shapes"), three
// launches over the table itself, every sum in sf_acc (sat_accum.clh) and every table entry
// hi + lo of an sf_acc:
// - sf_sat_scan_rows: a work-group of SF_SAT_WG items per S row r >= 1 (and the zero row 0)
//   and channel scans input row r - 1 in blocks of SF_SAT_WG texels (one per item, coalesced):
//   an inclusive Hillis-Steele scan in local memory plus the running total of the blocks before.
//   S[r][x + 1] then holds the row prefix (texels 0..x of the row); S[r][0] = 0.
// - sf_sat_scan_bands: one item per column and band (all but the last): the band's column sum
//   of the row prefixes into the scratch (N nb W entries).
// - sf_sat_scan_cols: one item per column and band: the sums of the bands above (in order),
//   then down the band's rows, S[r][x + 1] = S[r - 1][x + 1] + row prefix.
// A row prefix passes through the table as hi + lo (2^-47 of it: the double's split, or the
// normalised float-float pair exactly), which keeps every entry within the bound above.
// Partial groups: items past the row (scan) take zeros and reach every barrier; items past W
// (column passes, which have no barrier) return.
#ifdef SF_SAT_GPU

#if SF_SAT_FP64
inline sf_acc sf_sat_acc_of(float v) { return (double)v; }
inline sf_acc sf_sat_entry(__global const float* hi, __global const float* lo, size_t i) {
  return (double)hi[i] + (double)lo[i];
}
// sf_acc8_split for one entry: hi = the sum truncated to 24 significant bits, lo the rest.
inline void sf_sat_put_entry(__global float* hi, __global float* lo, size_t i, sf_acc d) {
  const double h = as_double(as_ulong(d) & 0xFFFFFFFFE0000000UL);
  hi[i] = (float)h;
  lo[i] = (float)(d - h);
}
#else
inline sf_acc sf_sat_acc_of(float v) { return (float2)(v, 0.0f); }
inline sf_acc sf_sat_entry(__global const float* hi, __global const float* lo, size_t i) {
  return (float2)(hi[i], lo[i]);
}
inline void sf_sat_put_entry(__global float* hi, __global float* lo, size_t i, sf_acc d) {
  hi[i] = d.x;
  lo[i] = d.y;
}
#endif

// NDRange (SF_SAT_WG, H + 1, N), local (SF_SAT_WG, 1, 1).
__kernel __attribute__((reqd_work_group_size(SF_SAT_WG, 1, 1))) void sf_sat_scan_rows(
    __global const sf_stored* restrict src, const int W, const int H, __global float* restrict sat) {
  __local sf_acc buf[2][SF_SAT_WG];
  const int lx = get_local_id(0), r = get_group_id(1), c = get_group_id(2);
  const size_t Wp = sf_sat_pitch(W), P = Wp * (H + 1);
  __global float* hi = sat + 2 * c * P + SF_SAT_X0 + (size_t)r * Wp;
  __global float* lo = hi + P;
  if (r == 0) {  // the whole group: no barrier follows
    for (int x = lx; x <= W; x += SF_SAT_WG) {
      hi[x] = 0.0f;
      lo[x] = 0.0f;
    }
    return;
  }
  if (lx == 0) {
    hi[0] = 0.0f;
    lo[0] = 0.0f;
  }
  __global const sf_stored* row = src + (size_t)c * W * H + (size_t)(r - 1) * W;
  sf_acc carry = SF_ACC_ZERO;  // the row's sum over the blocks before this one
  for (int x0 = 0; x0 < W; x0 += SF_SAT_WG) {
    const int x = x0 + lx;
    buf[0][lx] = sf_sat_acc_of(x < W ? sf_load(row, x) : 0.0f);
    barrier(CLK_LOCAL_MEM_FENCE);
    int cur = 0;
    for (int d = 1; d < SF_SAT_WG; d <<= 1) {
      buf[cur ^ 1][lx] = lx >= d ? sf_acc_add(buf[cur][lx - d], buf[cur][lx]) : buf[cur][lx];
      cur ^= 1;
      barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (x < W) sf_sat_put_entry(hi, lo, x + 1, sf_acc_add(carry, buf[cur][lx]));
    carry = sf_acc_add(carry, buf[cur][SF_SAT_WG - 1]);
    barrier(CLK_LOCAL_MEM_FENCE);  // every item has read buf before the next block writes it
  }
}

// NDRange (ceil(W / SF_SAT_WG) SF_SAT_WG, nb - 1, N), local (SF_SAT_WG, 1, 1). Band b: input rows
// [b band_rows, (b + 1) band_rows), S rows b band_rows + 1 .. on.
__kernel __attribute__((reqd_work_group_size(SF_SAT_WG, 1, 1))) void sf_sat_scan_bands(
    const int W, const int H, const int band_rows, const int nb, __global sf_acc* restrict scratch,
    __global const float* restrict sat) {
  const int x = get_global_id(0), b = get_global_id(1), c = get_global_id(2);
  if (x >= W) return;
  const size_t Wp = sf_sat_pitch(W), P = Wp * (H + 1);
  __global const float* hi = sat + 2 * c * P + SF_SAT_X0 + 1 + x;
  __global const float* lo = hi + P;
  sf_acc t = SF_ACC_ZERO;
  const int r1 = min(H, (b + 1) * band_rows);
  for (int r = b * band_rows + 1; r <= r1; ++r) t = sf_acc_add(t, sf_sat_entry(hi, lo, (size_t)r * Wp));
  scratch[(size_t)(c * nb + b) * W + x] = t;
}

// NDRange (ceil(W / SF_SAT_WG) SF_SAT_WG, nb, N), local (SF_SAT_WG, 1, 1).
__kernel __attribute__((reqd_work_group_size(SF_SAT_WG, 1, 1))) void sf_sat_scan_cols(
    const int W, const int H, const int band_rows, const int nb, __global const sf_acc* restrict scratch,
    __global float* restrict sat) {
  const int x = get_global_id(0), b = get_global_id(1), c = get_global_id(2);
  if (x >= W) return;
  const size_t Wp = sf_sat_pitch(W), P = Wp * (H + 1);
  __global float* hi = sat + 2 * c * P + SF_SAT_X0 + 1 + x;
  __global float* lo = hi + P;
  sf_acc t = SF_ACC_ZERO;
  for (int j = 0; j < b; ++j) t = sf_acc_add(t, scratch[(size_t)(c * nb + j) * W + x]);
  const int r1 = min(H, (b + 1) * band_rows);
  for (int r = b * band_rows + 1; r <= r1; ++r) {
    t = sf_acc_add(t, sf_sat_entry(hi, lo, (size_t)r * Wp));
    sf_sat_put_entry(hi, lo, (size_t)r * Wp, t);
  }
}

#else  // the Cpu family's schedules

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

// In-register 8x8 transpose (unpack, 4-lane shuffle, 128-bit lane permute: 24 shuffles). Clang
// gets them as explicit shuffles: from element-wise vector literals PoCL's LLVM built the same
// transposes from inserts and broadcasts, a longer and slower block loop (docs/lookups.md).
#if defined(__clang__)
#define SF_UNPACKLO(T, a, b) __builtin_shufflevector(a, b, 0, 8, 1, 9, 4, 12, 5, 13)
#define SF_UNPACKHI(T, a, b) __builtin_shufflevector(a, b, 2, 10, 3, 11, 6, 14, 7, 15)
#define SF_SHUFLO(T, a, b) __builtin_shufflevector(a, b, 0, 1, 8, 9, 4, 5, 12, 13)
#define SF_SHUFHI(T, a, b) __builtin_shufflevector(a, b, 2, 3, 10, 11, 6, 7, 14, 15)
#define SF_PERMLO(T, a, b) __builtin_shufflevector(a, b, 0, 1, 2, 3, 8, 9, 10, 11)
#define SF_PERMHI(T, a, b) __builtin_shufflevector(a, b, 4, 5, 6, 7, 12, 13, 14, 15)
#else
#define SF_UNPACKLO(T, a, b) (T)((a).s0, (b).s0, (a).s1, (b).s1, (a).s4, (b).s4, (a).s5, (b).s5)
#define SF_UNPACKHI(T, a, b) (T)((a).s2, (b).s2, (a).s3, (b).s3, (a).s6, (b).s6, (a).s7, (b).s7)
#define SF_SHUFLO(T, a, b) (T)((a).s0, (a).s1, (b).s0, (b).s1, (a).s4, (a).s5, (b).s4, (b).s5)
#define SF_SHUFHI(T, a, b) (T)((a).s2, (a).s3, (b).s2, (b).s3, (a).s6, (a).s7, (b).s6, (b).s7)
#define SF_PERMLO(T, a, b) (T)((a).lo, (b).lo)
#define SF_PERMHI(T, a, b) (T)((a).hi, (b).hi)
#endif
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

// sf_sat_chain: reads of a band's status (~1 ms) before the band below sums its rows itself.
// SF_SAT_SUM_ALL 1: every band sums all the rows above it (tests: the path of a preempted band).
#ifndef SF_SAT_POLLS
#define SF_SAT_POLLS (1 << 20)
#endif
#ifndef SF_SAT_SUM_ALL
#define SF_SAT_SUM_ALL 0
#endif
#ifndef SF_SAT_STRIP
#define SF_SAT_STRIP 256
#endif

// Column sums of rows y0 .. y1 - 1 (y1 > y0), columns xs .. xe - 1, into o[xs .. xe - 1], walking
// the rows in order (contiguous reads), the sums in o (in L1).
inline void sf_sat_colsums(__global const sf_stored* restrict plane, int W, int xs, int xe, int y0,
                           int y1, __global sf_acc* restrict o) {
  for (int x = xs; x < xe; x += 16)
    sf_acc16_put(o, x, xe, sf_acc16_of(sf_sat_load_stored(plane + (size_t)y0 * W, x, W)));
  int y = y0 + 1;
  // 4 rows per pass over the sums (a quarter of the sums' loads and stores).
  if (xe - xs >= 16)
    for (; y + 4 <= y1; y += 4) {
      __global const sf_stored* row = plane + (size_t)y * W;
      for (int x = xs; x + 16 <= xe; x += 16) {
        sf_acc16 a = sf_acc16_addf(sf_acc16_vload(o + x), SF_VLOAD(16, row, x));
        a = sf_acc16_addf(a, SF_VLOAD(16, row + W, x));
        a = sf_acc16_addf(a, SF_VLOAD(16, row + 2 * W, x));
        sf_acc16_vstore(o + x, sf_acc16_addf(a, SF_VLOAD(16, row + 3 * W, x)));
      }
      for (int x = xs + (xe - xs) / 16 * 16; x < xe; x += 16) {
        sf_acc16 a = sf_acc16_load(o, x, xe);
        for (int i = 0; i < 4; ++i) a = sf_acc16_addf(a, sf_sat_load_stored(row + i * W, x, W));
        sf_acc16_put(o, x, xe, a);
      }
    }
  for (; y < y1; ++y) {
    __global const sf_stored* row = plane + (size_t)y * W;
    int x = xs;
    for (; x + 16 <= xe; x += 16)
      sf_acc16_vstore(o + x, sf_acc16_addf(sf_acc16_vload(o + x), SF_VLOAD(16, row, x)));
    for (; x < xe; x += 16)
      sf_acc16_put(o, x, xe, sf_acc16_addf(sf_acc16_load(o, x, xe), sf_sat_load_stored(row, x, W)));
  }
}

// Band sums: scratch (sf_acc) holds, for channel c and band b, the column sums of the band's
// rows at (c nb + b) W. One work-item per SF_SAT_STRIP columns x band x channel.
// NDRange (ceil(W / SF_SAT_STRIP), nb, N), local (1, 1, 1).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_bands(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global sf_acc* restrict scratch) {
  const int xs = get_global_id(0) * SF_SAT_STRIP, b = get_global_id(1), c = get_global_id(2);
  const int y0 = b * band_rows;
  sf_sat_colsums(src + (size_t)c * W * H, W, xs, min(W, xs + SF_SAT_STRIP), y0, min(H, y0 + band_rows),
                 scratch + (size_t)(c * nb + b) * W);
}

// 8 rows x 8 columns of the band from column x (rows ys.., the running row totals t): the row
// prefixes h0..h7 (h_i = row ys + i's prefix at columns x..x+7), t advanced past column x + 7.
#define SF_SAT_T(r, h) \
  t = sf_acc8_addf(t, r);  \
  h = t;
#define SF_SAT_BLOCK8(r0, r1, r2, r3, r4, r5, r6, r7, h0, h1, h2, h3, h4, h5, h6, h7)              \
  {                                                                                                \
    SF_TRANSPOSE8(float8, r0, r1, r2, r3, r4, r5, r6, r7)                                          \
    SF_SAT_T(r0, h0) SF_SAT_T(r1, h1) SF_SAT_T(r2, h2) SF_SAT_T(r3, h3) SF_SAT_T(r4, h4)           \
    SF_SAT_T(r5, h5) SF_SAT_T(r6, h6) SF_SAT_T(r7, h7) SF_ACC_TRANSPOSE8(h0, h1, h2, h3, h4, h5, h6, h7) \
  }

// r0..r7 = 8 texels from column xx of the 8 stored rows from `in` (row pitch W).
#define SF_SAT_LOAD8(xx)                                                   \
  r0 = SF_VLOAD(8, in, xx);                                                \
  r1 = SF_VLOAD(8, in + W, xx);                                            \
  r2 = SF_VLOAD(8, in + 2 * W, xx);                                        \
  r3 = SF_VLOAD(8, in + 3 * W, xx);                                        \
  r4 = SF_VLOAD(8, in + 4 * W, xx);                                        \
  r5 = SF_VLOAD(8, in + 5 * W, xx);                                        \
  r6 = SF_VLOAD(8, in + 6 * W, xx);                                        \
  r7 = SF_VLOAD(8, in + 7 * W, xx);

// One band of rows y0 .. y1 - 1 of one channel (plane: its stored image; shi, slo: its table
// planes, SF_SAT_X0 applied) into S rows y0 .. y1 - 1 (and row H for the last band). S row y0 is
// the prefix along x of the column carries: the sum of the ncarry rows of W entries at cb. vrow:
// W entries of scratch for the running S row.
inline void sf_sat_band(__global const sf_stored* restrict plane, int W, int H, int y0, int y1,
                        bool last, __global const sf_acc* restrict cb, int ncarry,
                        __global sf_acc* restrict vrow, __global float* restrict shi,
                        __global float* restrict slo, bool lines) {
  const size_t Wp = sf_sat_pitch(W);
  {
    sf_acc t = SF_ACC_ZERO;
    __global float* rh = shi + (size_t)y0 * Wp;
    __global float* rl = slo + (size_t)y0 * Wp;
    rh[0] = 0.0f;
    rl[0] = 0.0f;
    for (int x = 0; x < W; x += 8) {
      sf_acc8 cs = sf_acc8_zero();
      for (int k = 0; k < ncarry; ++k) cs = sf_acc8_add(cs, sf_acc8_load(cb + (size_t)k * W, x, W));
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
  const int y_end = last ? y1 : y1 - 1;
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
    int x = 0;
    // Whole blocks of 8 rows x 16 columns: each row's 16 entries of S (hi and lo) leave as one
    // streamed line. S[y+1] = S[y] + row prefix, down the columns from the S row above (v).
    if (lines && nr == 8) {
      for (; x + 16 <= W; x += 16) {
        float8 r0, r1, r2, r3, r4, r5, r6, r7;
        SF_SAT_LOAD8(x)
        sf_acc8 h0, h1, h2, h3, h4, h5, h6, h7;
        SF_SAT_BLOCK8(r0, r1, r2, r3, r4, r5, r6, r7, h0, h1, h2, h3, h4, h5, h6, h7)
        SF_SAT_LOAD8(x + 8)
        sf_acc8 g0, g1, g2, g3, g4, g5, g6, g7;
        SF_SAT_BLOCK8(r0, r1, r2, r3, r4, r5, r6, r7, g0, g1, g2, g3, g4, g5, g6, g7)
        sf_acc8 va = sf_acc8_vload(vrow + x), vb = sf_acc8_vload(vrow + x + 8);
        float8 ah, al, bh, bl;
#define SF_OUT16(i)                                                \
  va = sf_acc8_add(va, h##i);                                      \
  vb = sf_acc8_add(vb, g##i);                                      \
  sf_acc8_split(va, &ah, &al);                                     \
  sf_acc8_split(vb, &bh, &bl);                                     \
  sf_stream16(oh + (size_t)(i) * Wp + x, (float16)(ah, bh));   \
  sf_stream16(ol + (size_t)(i) * Wp + x, (float16)(al, bl));
        SF_OUT16(0) SF_OUT16(1) SF_OUT16(2) SF_OUT16(3) SF_OUT16(4) SF_OUT16(5) SF_OUT16(6) SF_OUT16(7)
#undef SF_OUT16
        sf_acc8_vstore(vrow + x, va);
        sf_acc8_vstore(vrow + x + 8, vb);
      }
    }
    // The rest in blocks of 8 x 8 (rows past nr and columns past W read as zeros), plain stores.
    for (; x < W; x += 8) {
      const bool full = nr == 8 && x + 8 <= W;
      float8 r0, r1, r2, r3, r4, r5, r6, r7;
      if (full) {
        SF_SAT_LOAD8(x)
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
      sf_acc8 h0, h1, h2, h3, h4, h5, h6, h7;
      SF_SAT_BLOCK8(r0, r1, r2, r3, r4, r5, r6, r7, h0, h1, h2, h3, h4, h5, h6, h7)
      // Rows past nr are zero (their prefixes too): v ends as S row ys + nr.
      sf_acc8 v = sf_acc8_load(vrow, x, W);
      float8 fh, fl;
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

// Whole lines can be streamed when the table starts on one (it does in any buffer the host
// allocates; a sub-buffer at an odd offset takes plain stores).
inline bool sf_sat_lines(__global const float* sat) { return ((size_t)sat & 63) == 0; }

// Second launch of the two-launch build. NDRange (nb, N), local (1, 1): see the file comment.
// scratch: the band sums (N nb W entries) then one row of W entries per band and channel (the
// band's running S row, unrounded).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_rows(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global sf_acc* restrict scratch, __global float* restrict sat) {
  const int b = get_global_id(0), c = get_global_id(1), N = get_global_size(1);
  const size_t P = sf_sat_pitch(W) * (H + 1);
  __global float* shi = sat + 2 * c * P + SF_SAT_X0;
  sf_sat_band(src + (size_t)c * W * H, W, H, b * band_rows, min(H, (b + 1) * band_rows), b == nb - 1,
              scratch + (size_t)c * nb * W, b, scratch + (size_t)(N * nb + c * nb + b) * W, shi, shi + P,
              sf_sat_lines(sat));
}

// dst = a (n == 0) or dst + a (n > 0), W entries.
inline void sf_sat_accumulate(__global sf_acc* restrict dst, __global const sf_acc* restrict a, int W,
                              int n) {
  for (int x = 0; x < W; x += 8)
    sf_acc8_put(dst, x, W,
                n == 0 ? sf_acc8_load(a, x, W) : sf_acc8_add(sf_acc8_load(dst, x, W), sf_acc8_load(a, x, W)));
}

// The one-launch build (CPUs): band t = (channel t / nb, band t % nb) in the order the work-items
// start (tickets), each reading its band twice, the second time from cache. NDRange (nb N),
// local (1). Nothing waits for long (a decoupled look-back, as in single-pass prefix scans): a
// band publishes the column sums of its rows (status 1), then walks up the bands above adding
// their published sums until one has published its inclusive carries (status 2: the column sums
// of every row down to its last); a band above that has published nothing after SF_SAT_POLLS
// reads (its work-item was preempted, say) is summed here from its rows. The band then publishes
// its own inclusive carries and builds its rows from the exclusive ones.
// scratch: 4 nb N rows of W entries (per band: its sums, its inclusive carries, its exclusive
// carries, its running S row), then the control ints, zero before the launch (the host fills
// them): ctl[0] hands out the tickets, ctl[1 + t] is band t's status (0, 1, 2).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_sat_chain(
    __global const sf_stored* restrict src, const int W, const int H, const int band_rows,
    const int nb, __global sf_acc* restrict scratch, __global float* restrict sat) {
  const int total = get_global_size(0);
  volatile __global int* ctl = (volatile __global int*)(scratch + (size_t)4 * total * W);
  volatile __global int* status = ctl + 1;
  const int t = atomic_inc(ctl);
  const int c = t / nb, b = t % nb, y0 = b * band_rows, y1 = min(H, y0 + band_rows);
  const bool last = b == nb - 1;
#define SF_SAT_ROW(k, band) (scratch + ((size_t)(k) * total + (band)) * W)
  __global const sf_stored* plane = src + (size_t)c * W * H;
  __global sf_acc* sums = SF_SAT_ROW(0, t);
  __global sf_acc* incl = SF_SAT_ROW(1, t);
  __global sf_acc* excl = SF_SAT_ROW(2, t);
  __global sf_acc* vrow = SF_SAT_ROW(3, t);
  if (!last) {
    sf_sat_colsums(plane, W, 0, W, y0, y1, b == 0 ? incl : sums);
    mem_fence(CLK_GLOBAL_MEM_FENCE);
    atomic_xchg(status + t, b == 0 ? 2 : 1);
  }
  int n = 0;  // rows added into excl
  for (int j = b - 1; j >= 0; --j) {
    const int tj = t - (b - j);
    // The band above usually started with this one and publishes within a band's column sums:
    // wait a little (plain reads) before summing its rows here.
    for (int poll = 0; poll < SF_SAT_POLLS && status[tj] == 0; ++poll) {
    }
    const int st = SF_SAT_SUM_ALL ? 0 : atomic_add(status + tj, 0);
    __global const sf_acc* add = vrow;
    if (st == 2)
      add = SF_SAT_ROW(1, tj);
    else if (st == 1)
      add = SF_SAT_ROW(0, tj);
    else
      sf_sat_colsums(plane, W, 0, W, j * band_rows, (j + 1) * band_rows, vrow);
    sf_sat_accumulate(excl, add, W, n++);
    if (st == 2) break;
  }
  if (!last && b > 0) {
    sf_sat_accumulate(incl, excl, W, 0);
    sf_sat_accumulate(incl, sums, W, 1);
    mem_fence(CLK_GLOBAL_MEM_FENCE);
    atomic_xchg(status + t, 2);
  }
#undef SF_SAT_ROW
  const size_t P = sf_sat_pitch(W) * (H + 1);
  __global float* shi = sat + 2 * c * P + SF_SAT_X0;
  sf_sat_band(plane, W, H, y0, y1, last, excl, b > 0 ? 1 : 0, vrow, shi, shi + P, sf_sat_lines(sat));
}

#endif  // SF_SAT_GPU
