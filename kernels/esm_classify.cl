// ESM failure classification and fall-back (Annen 2008 ch. 7.3; methods.md sec. 3; docs/lookups.md).
// Needs common.clh, storage.clh, methods/esm.clh, lookup.clh (SF_LOOKUP) and receiver_plane.clh
// before it. Runs after reconstruction: flagged receivers get a 2x2 PCF of the ESM test on the raw
// depth against their plane instead.
//
// Modes: 1 = zmax: flag when some depth texel in the lookup's support has z > d + offset. The
// support (every texel with a non-zero composite weight, and possibly a few zero-weight ones) is
// bounded by a box in level-0 texels; the z-max pyramid is read at the finest level where the
// box spans at most 8x8 texels, whose max covers the box: conservative, it never misses.
// 2 = threshold: flag when exp(-c d) bar(B) > 1 + eps, i.e. log bar(B') - c (d - 1/2) > log1p(eps).

// Level-0 box [lo.x, hi.x] x [lo.y, hi.y] of the lookup's support before the prefilter.
inline int4 sf_support(int W, int H, float u, float v, float f) {
#if SF_LOOKUP == SF_LOOKUP_SAT
  const float s = 0.5f * (isfinite(f) ? fmax(f, 1.0f) : 1.0f);
  const float X0 = fma(u, (float)W, -s), X1 = fma(u, (float)W, s);
  const float Y0 = fma(v, (float)H, -s), Y1 = fma(v, (float)H, s);
  return (int4)(sf_clampi((int)floor(X0), 0, W - 1), sf_clampi((int)floor(Y0), 0, H - 1),
                sf_clampi((int)ceil(X1) - 1, 0, W - 1), sf_clampi((int)ceil(Y1) - 1, 0, H - 1));
#else
  int k0 = 0, k1 = 0;
#if SF_LOOKUP == SF_LOOKUP_MIPS
  float t;
  k0 = sf_lod(f, sf_mip_top(W, H), &t);
  k1 = t > 0.0f ? k0 + 1 : k0;
#endif
  int4 box = (int4)(W, H, -1, -1);
  for (int k = k0; k <= k1; ++k) {
    int w, h;
    size_t off;
    sf_mip_level(W, H, 1, k, &w, &h, &off);
    const int x = (int)floor(fma(u, (float)w, -0.5f)), y = (int)floor(fma(v, (float)h, -0.5f));
    // Level-k texels x..x+1 (clamped) cover level-0 texels [x 2^k, (x+2) 2^k - 1] (clamped).
    const int xa = sf_clampi(x, 0, w - 1), xb = sf_clampi(x + 1, 0, w - 1);
    const int ya = sf_clampi(y, 0, h - 1), yb = sf_clampi(y + 1, 0, h - 1);
    box.x = min(box.x, xa << k);
    box.y = min(box.y, ya << k);
    box.z = max(box.z, min(((xb + 1) << k) - 1, W - 1));
    box.w = max(box.w, min(((yb + 1) << k) - 1, H - 1));
  }
  return box;
#endif
}

// Max depth over the level-0 box, from the z-max pyramid (level 0 = depth, levels >= 1 = chain):
// the finest level where the box spans at most 8x8 texels, all of them read (64 fetches at most).
// Coarser fetches over-cover: a level's aligned blocks reach up to (1 + 2/span) past the box
// (a 2x2 fetch: 2x), and a Gaussian fringe of R texels around a trilinear footprint aligned at
// level k costs a whole extra block of 2^k per side.
inline float sf_zmax_box(__global const float* restrict depth, __global const float* restrict zchain,
                         int W, int H, int4 box) {
  int k = 0;
  while (((box.z >> k) - (box.x >> k)) > 7 || ((box.w >> k) - (box.y >> k)) > 7) ++k;
  int w, h;
  size_t off;
  sf_mip_level(W, H, 1, k, &w, &h, &off);
  __global const float* z = k == 0 ? depth : zchain + off;
  float m = 0.0f;
  for (int y = box.y >> k; y <= (box.w >> k); ++y)
    for (int x = box.x >> k; x <= (box.z >> k); ++x) m = fmax(m, z[(size_t)y * w + x]);
  return m;
}

// 2x2 PCF of the ESM test against the receiver's plane p (receiver_plane.clh): bilinear weights
// at (p->x, p->y) on min(exp(c (z_t - d_t + bias)), 1) per depth texel t, d_t the plane at t.
inline float sf_esm_pcf2x2(__global const float* restrict depth, int W, int H, const sf_plane* p,
                           float bias, float c) {
  const float x = p->x, y = p->y;
  const float xf = floor(x), yf = floor(y), ax = x - xf, ay = y - yf;
  const int x0 = sf_clampi((int)xf, 0, W - 1), x1 = sf_clampi((int)xf + 1, 0, W - 1);
  const int y0 = sf_clampi((int)yf, 0, H - 1), y1 = sf_clampi((int)yf + 1, 0, H - 1);
#define SF_T(X, Y) \
  exp(fmin(c * (depth[(size_t)(Y) * W + (X)] - sf_plane_at(p, (float)(X), (float)(Y)) + bias), 0.0f))
  return mix(mix(SF_T(x0, y0), SF_T(x1, y0), ax), mix(SF_T(x0, y1), SF_T(x1, y1), ax), ay);
#undef SF_T
}


// Whether one receiver at depth d is flagged. box: the lookup's support before the prefilter
// (zmax mode); b: the filtered basis as the reconstruction read it (threshold mode). A flagged
// receiver's fall-back (sf_esm_pcf2x2) tests against its plane, which only flagged receivers
// compute.
inline bool sf_classify(__global const float* restrict depth, __global const float* restrict zchain, int W,
                        int H, float d, int4 box, const float* b, const sf_classify_params C,
                        const sf_method_params P) {
  if (C.mode == SF_CLASSIFY_ZMAX) {
    box = (int4)(max(box.x - C.radius, 0), max(box.y - C.radius, 0), min(box.z + C.radius, W - 1),
                 min(box.w + C.radius, H - 1));
    return sf_zmax_box(depth, zchain, W, H, box) > d + C.offset;
  }
  return log(fmax(b[0], FLT_MIN)) - P.c * (d - 0.5f) > C.log_thresh;
}

__kernel void sf_esm_classify_points(
    __global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
    __global const float* restrict sat, __global const float* restrict depth,
    __global const float* restrict zchain, const int W, const int H,
    __global const float* restrict u, __global const float* restrict v,
    __global const float* restrict d, __global const float* restrict f,
    __global float* restrict out, __global uchar* restrict flags, const int count,
    const sf_classify_params C, const sf_method_params P, const sf_plane_params PP) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    flags[i] = 0;
    return;
  }
  const float fi = f ? f[i] : 1.0f;
  float b[SF_CHANNELS] = {0.0f};
  if (C.mode == SF_CLASSIFY_THRESHOLD) sf_lookup(basis, chain, sat, W, H, ui, vi, fi, b);
  const float dd = clamp(di, 0.0f, 1.0f);
  const bool flag = sf_classify(depth, zchain, W, H, dd, sf_support(W, H, ui, vi, fi), b, C, P);
  flags[i] = flag ? 1 : 0;
  if (flag) {
    const sf_plane p = sf_receiver_plane_points(i, count, u, v, d, depth, W, H, ui, vi, dd, PP);
    out[i] = clamp(sf_esm_pcf2x2(depth, W, H, &p, sf_plane_bias(&p, 0.0f, PP), P.c), 0.0f, 1.0f);
  }
}

// --receiver-depth mode: receivers at texel centres, footprint 1.
__kernel void sf_esm_classify_grid(
    __global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
    __global const float* restrict sat, __global const float* restrict depth,
    __global const float* restrict zchain, const int W, const int H,
    __global const float* restrict d, __global float* restrict out, __global uchar* restrict flags,
    const sf_classify_params C, const sf_method_params P, const sf_plane_params PP) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= W || y >= H) return;
  const size_t i = (size_t)y * W + x;
  const float di = d[i];
  if (!isfinite(di)) {
    flags[i] = 0;
    return;
  }
  const float ui = ((float)x + 0.5f) / (float)W, vi = ((float)y + 0.5f) / (float)H;
  float b[SF_CHANNELS] = {0.0f};
  if (C.mode == SF_CLASSIFY_THRESHOLD) sf_lookup_texel(basis, W, W * H, x, y, b);  // as sf_reconstruct_grid reads it
  const float dd = clamp(di, 0.0f, 1.0f);
  const bool flag = sf_classify(depth, zchain, W, H, dd, (int4)(x, y, x, y), b, C, P);
  flags[i] = flag ? 1 : 0;
  if (flag) {
    const sf_plane p = sf_receiver_plane_grid(d, depth, W, H, x, y, dd, PP);
    out[i] = clamp(sf_esm_pcf2x2(depth, W, H, &p, sf_plane_bias(&p, 0.0f, PP), P.c), 0.0f, 1.0f);
  }
}
