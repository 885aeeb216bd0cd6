// Mip pyramids of planar N-channel images (methods.md sec. 2): level k+1 texel (i, j) reduces
// level-k texels (2i..2i+1, 2j..2j+1), indices clamped to level k; sizes ceil(n/2) down to 1x1.
// Needs common.clh (sf_mip_level), storage.clh and vecio.clh before it.
//
// Knob SF_REDUCE: 0 = mean (basis images), 1 = max (z-max pyramid), 2 = min (z-min pyramid).
// The mean is 0.25 * ((a + b) + (c + d)) with (a, b) the upper pair and (c, d) the lower pair,
// the order the scalar reference documents.
//
// Two kernels build the chain in few launches (PoCL pays ~0.2 ms per launch):
// - sf_pyramid_tiles: one work-item per SF_WIDE (4) 32x32 tiles side by side of a level s and
//   channel; produces up to SF_TILE_LEVELS (5) levels below s from each tile alone. Clamping
//   never leaves a tile: a level-(s+j) texel reads level-s texels [i 2^j, (i+1) 2^j) clamped to
//   the level, and the clamped index lies in the last tile. Interior tiles (fully inside level
//   s) take a vector path with no clamping at any level; when all SF_WIDE are interior, their
//   rows are read and written as one run per row (512 bytes of level s, whole cache lines of
//   level s+1) instead of 128-byte pieces of 32 rows per work-item.
// - sf_pyramid_tail: one work-item per channel finishes the small levels down to 1x1.

#if SF_REDUCE == 0
#define SF_RED(a, b, c, d) (0.25f * (((a) + (b)) + ((c) + (d))))
#elif SF_REDUCE == 1
#define SF_RED(a, b, c, d) fmax(fmax((a), (b)), fmax((c), (d)))
#elif SF_REDUCE == 2
#define SF_RED(a, b, c, d) fmin(fmin((a), (b)), fmin((c), (d)))
#else
#error "SF_REDUCE must be 0 (mean), 1 (max) or 2 (min)"
#endif

#define SF_TILE 32
#define SF_TILE_LEVELS 5
#ifndef SF_WIDE
#define SF_WIDE 4
#endif

// Reduces rows 2r, 2r+1 of `n2` texels (vectors a = row 2r, b = row 2r + 1) to n2/2 texels.
#define SF_RED_VEC(a, b) SF_RED((a).even, (a).odd, (b).even, (b).odd)

// Element pointer of level k's plane c: level 0 is `level0`, levels >= 1 live in `chain`.
inline __global sf_stored* sf_level_plane(__global sf_stored* level0, __global sf_stored* chain,
                                          int W, int H, int N, int k, int c, int* w, int* h) {
  size_t off;
  sf_mip_level(W, H, N, k, w, h, &off);
  if (k == 0) return level0 + (size_t)c * W * H;
  return chain + off + (size_t)c * (*w) * (*h);
}

#ifndef SF_PYRAMID_GPU  // the Cpu family

// n (1 or SF_WIDE) interior tiles side by side at (x0, y0) of level s: vector path, produces
// `m` levels. Every row of every level is read and written as one run of n tiles (with n =
// SF_WIDE rows of 32 SF_WIDE texels, full cache lines from level 1 on, instead of 128-byte
// pieces of 32 rows at a time). Callers pass n as a constant: inlined, the loops over t unroll
// and the arrays stay in registers.
inline __attribute__((always_inline)) void sf_tiles_interior(
    __global const sf_stored* src, int ws, int x0, int y0, const int n, int m,
    __global sf_stored* chain, int W, int H, int N, int s, int c) {
  int w, h;
  float16 l1[SF_WIDE][16];
  {
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 1, c, &w, &h);
#if SF_STORAGE == 0
    // Level s + 1 in whole 64-byte lines past the caches where its rows lie on lines: the chain
    // build reads it again only when it is the launch's last level (m == 1), and the largest
    // level's stores would otherwise read every line first (4 channels at 2048^2: 16 MiB).
    const bool stream =
        m >= 2 && (((size_t)(dst + (size_t)(y0 / 2) * w + x0 / 2) | ((size_t)w * sizeof(float))) & 63) == 0;
#endif
    for (int r = 0; r < 16; ++r) {
      const size_t a = (size_t)(y0 + 2 * r) * ws + x0, b = a + ws;
      const size_t o = (size_t)(y0 / 2 + r) * w + x0 / 2;
      for (int t = 0; t < n; ++t) {
        const float16 a0 = SF_VLOAD(16, src, a + 32 * t), a1 = SF_VLOAD(16, src, a + 32 * t + 16);
        const float16 b0 = SF_VLOAD(16, src, b + 32 * t), b1 = SF_VLOAD(16, src, b + 32 * t + 16);
        const float16 v = (float16)(SF_RED_VEC(a0, b0), SF_RED_VEC(a1, b1));
        l1[t][r] = v;
#if SF_STORAGE == 0
        if (stream)
          sf_stream16(dst + o + 16 * t, v);
        else
#endif
          SF_VSTORE(16, v, dst, o + 16 * t);
      }
    }
  }
  if (m < 2) return;
  float8 l2[SF_WIDE][8];
  {
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 2, c, &w, &h);
    for (int r = 0; r < 8; ++r)
      for (int t = 0; t < n; ++t) {
        l2[t][r] = SF_RED_VEC(l1[t][2 * r], l1[t][2 * r + 1]);
        SF_VSTORE(8, l2[t][r], dst, (size_t)(y0 / 4 + r) * w + x0 / 4 + 8 * t);
      }
  }
  if (m < 3) return;
  float4 l3[SF_WIDE][4];
  {
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 3, c, &w, &h);
    for (int r = 0; r < 4; ++r)
      for (int t = 0; t < n; ++t) {
        l3[t][r] = SF_RED_VEC(l2[t][2 * r], l2[t][2 * r + 1]);
        SF_VSTORE(4, l3[t][r], dst, (size_t)(y0 / 8 + r) * w + x0 / 8 + 4 * t);
      }
  }
  if (m < 4) return;
  float2 l4[SF_WIDE][2];
  {
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 4, c, &w, &h);
    for (int r = 0; r < 2; ++r)
      for (int t = 0; t < n; ++t) {
        l4[t][r] = SF_RED_VEC(l3[t][2 * r], l3[t][2 * r + 1]);
        SF_VSTORE(2, l4[t][r], dst, (size_t)(y0 / 16 + r) * w + x0 / 16 + 2 * t);
      }
  }
  if (m < 5) return;
  {
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 5, c, &w, &h);
    for (int t = 0; t < n; ++t)
      sf_store(dst, (size_t)(y0 / 32) * w + x0 / 32 + t,
               SF_RED(l4[t][0].x, l4[t][0].y, l4[t][1].x, l4[t][1].y));
  }
}

// Edge tile: scalar, with the clamping of methods.md at every level. The tile is reduced in
// place (row stride SF_TILE): output (j, i) reads (2j.., 2i..), never an earlier output.
inline void sf_tile_edge(__global const sf_stored* src, int ws, int hs, int x0, int y0, int m,
                         __global sf_stored* chain, int W, int H, int N, int s, int c) {
  float t[SF_TILE * SF_TILE];
  // Valid extent of the tile in the current level (local coordinates).
  int vw = min(SF_TILE, ws - x0), vh = min(SF_TILE, hs - y0);
  for (int j = 0; j < vh; ++j)
    for (int i = 0; i < vw; ++i) t[j * SF_TILE + i] = sf_load(src, (size_t)(y0 + j) * ws + x0 + i);
  int size = SF_TILE, lx0 = x0, ly0 = y0;
  for (int k = 1; k <= m; ++k) {
    int w, h;
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + k, c, &w, &h);
    size >>= 1;
    lx0 >>= 1;
    ly0 >>= 1;
    const int nw = min(size, w - lx0), nh = min(size, h - ly0);
    for (int j = 0; j < nh; ++j) {
      const int j0 = 2 * j, j1 = min(2 * j + 1, vh - 1);
      for (int i = 0; i < nw; ++i) {
        const int i0 = 2 * i, i1 = min(2 * i + 1, vw - 1);
        const float r = SF_RED(t[j0 * SF_TILE + i0], t[j0 * SF_TILE + i1], t[j1 * SF_TILE + i0],
                               t[j1 * SF_TILE + i1]);
        t[j * SF_TILE + i] = r;
        sf_store(dst, (size_t)(ly0 + j) * w + lx0 + i, r);
      }
    }
    vw = nw;
    vh = nh;
  }
}

// NDRange (ceil(ws / (32 SF_WIDE)), ceil(hs / 32), N), local (1, 1, 1): one work-item per
// SF_WIDE tiles side by side. `src` + `src_off` is level s (level 0's buffer, or the chain
// itself); writes levels s+1 .. s+m (m <= 5) into `chain`.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_pyramid_tiles(
    __global const sf_stored* src, const int src_off, __global sf_stored* chain, const int W,
    const int H, const int N, const int s, const int m) {
  const int xw = get_global_id(0) * SF_TILE * SF_WIDE, y0 = get_global_id(1) * SF_TILE;
  const int c = get_global_id(2);
  int ws, hs;
  size_t unused;
  sf_mip_level(W, H, N, s, &ws, &hs, &unused);
  if (xw >= ws || y0 >= hs) return;
  __global const sf_stored* plane = src + src_off + (size_t)c * ws * hs;
  if (xw + SF_TILE * SF_WIDE <= ws && y0 + SF_TILE <= hs) {
    sf_tiles_interior(plane, ws, xw, y0, SF_WIDE, m, chain, W, H, N, s, c);
    return;
  }
  for (int x0 = xw; x0 < min(ws, xw + SF_TILE * SF_WIDE); x0 += SF_TILE) {
    if (x0 + SF_TILE <= ws && y0 + SF_TILE <= hs)
      sf_tiles_interior(plane, ws, x0, y0, 1, m, chain, W, H, N, s, c);
    else
      sf_tile_edge(plane, ws, hs, x0, y0, m, chain, W, H, N, s, c);
  }
}

// NDRange (N): one work-item per channel reduces level s (at src + src_off) down to 1x1,
// level by level through global memory (a work-item sees its own writes).
__kernel void sf_pyramid_tail(__global const sf_stored* src, const int src_off,
                              __global sf_stored* chain, const int W, const int H, const int N,
                              const int s) {
  const int c = get_global_id(0);
  if (c >= N) return;
  int pw, ph;
  size_t poff;
  sf_mip_level(W, H, N, s, &pw, &ph, &poff);
  __global const sf_stored* prev = src + src_off + (size_t)c * pw * ph;
  for (int k = s + 1; pw > 1 || ph > 1; ++k) {
    int w, h;
    __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, k, c, &w, &h);
    for (int j = 0; j < h; ++j) {
      const size_t r0 = (size_t)(2 * j) * pw, r1 = (size_t)min(2 * j + 1, ph - 1) * pw;
      for (int i = 0; i < w; ++i) {
        const int i0 = 2 * i, i1 = min(2 * i + 1, pw - 1);
        sf_store(dst, (size_t)j * w + i,
                 SF_RED(sf_load(prev, r0 + i0), sf_load(prev, r0 + i1), sf_load(prev, r1 + i0),
                        sf_load(prev, r1 + i1)));
      }
    }
    prev = dst;
    pw = w;
    ph = h;
  }
}
#endif  // !SF_PYRAMID_GPU

// The Gpu family (SF_PYRAMID_GPU; docs/gpu.md, "Launch shapes"): sf_pyramid_groups, work-groups
// of SF_PG x SF_PG items, one per texel of level s + 1 (its 2x2 texels of level s loaded with the
// clamping of methods.md, coalesced along rows), then up to log2(SF_PG) further levels from the
// group's tile in local memory, one barrier-separated step per level with the active items
// halving each way. As in sf_pyramid_tiles, clamping never leaves a tile (the tiles are aligned
// powers of two), levels within a launch are reduced from the unrounded float values and each
// value is rounded once when stored. Items outside a level compute nothing and still reach every
// barrier. NDRange (ceil(w / SF_PG) SF_PG, ceil(h / SF_PG) SF_PG, N) for level s + 1 of w x h.
#ifdef SF_PYRAMID_GPU
__kernel __attribute__((reqd_work_group_size(SF_PG, SF_PG, 1))) void sf_pyramid_groups(
    __global const sf_stored* src, const int src_off, __global sf_stored* chain, const int W,
    const int H, const int N, const int s, const int m) {
  __local float buf[SF_PG * SF_PG];
  const int lx = get_local_id(0), ly = get_local_id(1), c = get_global_id(2);
  int bx = get_group_id(0) * SF_PG, by = get_group_id(1) * SF_PG;  // the tile's origin in level s + 1
  int ws, hs, w, h;
  size_t unused;
  sf_mip_level(W, H, N, s, &ws, &hs, &unused);
  __global const sf_stored* plane = src + src_off + (size_t)c * ws * hs;
  __global sf_stored* dst = sf_level_plane(0, chain, W, H, N, s + 1, c, &w, &h);
  const int i = bx + lx, j = by + ly;
  float v = 0.0f;
  if (i < w && j < h) {
    const size_t r0 = (size_t)(2 * j) * ws, r1 = (size_t)min(2 * j + 1, hs - 1) * ws;
    const int i0 = 2 * i, i1 = min(2 * i + 1, ws - 1);
    v = SF_RED(sf_load(plane, r0 + i0), sf_load(plane, r0 + i1), sf_load(plane, r1 + i0),
               sf_load(plane, r1 + i1));
    sf_store(dst, (size_t)j * w + i, v);
  }
  buf[ly * SF_PG + lx] = v;
  // The tile's valid extent in the level just made (local coordinates).
  int vw = min(SF_PG, w - bx), vh = min(SF_PG, h - by), size = SF_PG;
  for (int k = 2; k <= m; ++k) {
    barrier(CLK_LOCAL_MEM_FENCE);
    size >>= 1;
    bx >>= 1;
    by >>= 1;
    dst = sf_level_plane(0, chain, W, H, N, s + k, c, &w, &h);
    const int nw = min(size, w - bx), nh = min(size, h - by);
    const bool active = lx < nw && ly < nh;
    float r = 0.0f;
    if (active) {
      const int i0 = 2 * lx, i1 = min(2 * lx + 1, vw - 1), j0 = 2 * ly, j1 = min(2 * ly + 1, vh - 1);
      r = SF_RED(buf[j0 * SF_PG + i0], buf[j0 * SF_PG + i1], buf[j1 * SF_PG + i0], buf[j1 * SF_PG + i1]);
      sf_store(dst, (size_t)(by + ly) * w + bx + lx, r);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (active) buf[ly * SF_PG + lx] = r;
    vw = nw;
    vh = nh;
  }
}
#endif  // SF_PYRAMID_GPU
