// ESM failure classification and fall-back (Annen 2008 ch. 7.3; methods.md sec. 3; docs/lookups.md).
// Needs common.clh, storage.clh, methods/esm.clh, lookup.clh (SF_LOOKUP) and receiver_plane.clh
// before it. Runs after reconstruction: flagged receivers get a 2x2 PCF of the ESM test on the raw
// depth against their plane instead.
//
// Modes: 1 = zmax: flag when some depth texel in the lookup's support, widened by the blur's
// radius R, has z > d + offset. It reads the dilated z-max pyramid (classify.hpp,
// enqueue_zmax_pyramid): zbase = the depth max-filtered over (2R+1)^2 (clamped), zchain its
// Reduce::Max pyramid, so that a level-k texel holds the max of the depth over its 2^k block
// widened by R. The blur's fringe is then in every texel, and a support of level-k texels reads
// those texels only: grid receivers read 1 texel, bilinear and trilinear lookups the 2x2 of their
// (coarser) level, exactly the support's bounding box widened by R; the SAT's box reads the 2x2
// (at most) of the finest level whose aligned blocks cover it, which may reach up to 4x the box
// per axis past it: conservative, it never misses.
// 2 = threshold: flag when exp(-c d) bar(B) > 1 + eps, i.e. log bar(B') - c (d - 1/2) > log1p(eps).

// Level k of a W x H map is ((W - 1) >> k) + 1 texels wide (sf_mip_level halves rounding up).
inline int sf_level_size(int n, int k) { return ((n - 1) >> k) + 1; }

// Max of level k (0: zbase) over its texels [x0, x1] x [y0, y1] (at most 2x2), clamped.
inline float sf_zmax_texels(__global const float* restrict zbase, __global const float* restrict zchain,
                            const sf_classify_params* C, int W, int H, int k, int x0, int y0, int x1,
                            int y1) {
  const int w = sf_level_size(W, k), h = sf_level_size(H, k);
  __global const float* z = k == 0 ? zbase : zchain + C->zoff[k];
  x0 = sf_clampi(x0, 0, w - 1), x1 = sf_clampi(x1, 0, w - 1);
  y0 = sf_clampi(y0, 0, h - 1), y1 = sf_clampi(y1, 0, h - 1);
  return fmax(fmax(z[(size_t)y0 * w + x0], z[(size_t)y0 * w + x1]),
              fmax(z[(size_t)y1 * w + x0], z[(size_t)y1 * w + x1]));
}

// Max of the 2x2 texels of level k that its bilinear lookup at (u, v) weighs.
inline float sf_zmax_level(__global const float* restrict zbase, __global const float* restrict zchain,
                           const sf_classify_params* C, int W, int H, int k, float u, float v) {
  const int w = sf_level_size(W, k), h = sf_level_size(H, k);
  const int x = (int)floor(fma(u, (float)w, -0.5f)), y = (int)floor(fma(v, (float)h, -0.5f));
  return sf_zmax_texels(zbase, zchain, C, W, H, k, x, y, x + 1, y + 1);
}

// Max depth over the lookup's support at (u, v, f), widened by R, from the dilated pyramid.
inline float sf_zmax_support(__global const float* restrict zbase, __global const float* restrict zchain,
                             const sf_classify_params* C, int W, int H, float u, float v, float f) {
#if SF_LOOKUP == SF_LOOKUP_SAT
  // The level-0 box of the box filter; the finest level where it spans at most 2x2 texels.
  const float s = 0.5f * (isfinite(f) ? fmax(f, 1.0f) : 1.0f);
  const int x0 = sf_clampi((int)floor(fma(u, (float)W, -s)), 0, W - 1);
  const int y0 = sf_clampi((int)floor(fma(v, (float)H, -s)), 0, H - 1);
  const int x1 = sf_clampi((int)ceil(fma(u, (float)W, s)) - 1, 0, W - 1);
  const int y1 = sf_clampi((int)ceil(fma(v, (float)H, s)) - 1, 0, H - 1);
  int k = 0;
  while ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1) ++k;
  return sf_zmax_texels(zbase, zchain, C, W, H, k, x0 >> k, y0 >> k, x1 >> k, y1 >> k);
#else
  int k0 = 0;
  float t = 0.0f;
#if SF_LOOKUP == SF_LOOKUP_MIPS
  k0 = sf_lod(f, C->top, &t);
#endif
  if (t <= 0.0f) return sf_zmax_level(zbase, zchain, C, W, H, k0, u, v);
  // Trilinear: the coarser level's 2x2 covers the finer one's where the finer level has even
  // sides (then its 2x2 lies in the coarser 2x2's 4x4 texels); odd sides read both.
  const float m1 = sf_zmax_level(zbase, zchain, C, W, H, k0 + 1, u, v);
  return ((sf_level_size(W, k0) | sf_level_size(H, k0)) & 1) ? fmax(m1, sf_zmax_level(zbase, zchain, C, W, H, k0, u, v))
                                                              : m1;
#endif
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


// Whether one receiver at depth d is flagged. zmax: the max depth over its widened support
// (sf_zmax_support); b: the filtered basis as the reconstruction read it (threshold mode). A
// flagged receiver's fall-back (sf_esm_pcf2x2) tests against its plane, which only flagged
// receivers compute.
inline bool sf_classify(float d, float zmax, const float* b, const sf_classify_params C, const sf_method_params P) {
  if (C.mode == SF_CLASSIFY_ZMAX) return zmax > d + C.offset;
  return log(fmax(b[0], FLT_MIN)) - P.c * (d - 0.5f) > C.log_thresh;
}

// The fall-back of one flagged receiver i at clamped depth dd: its plane, then the 2x2 PCF.
inline void sf_classify_fallback(int i, int count, __global const float* restrict u,
                                 __global const float* restrict v, __global const float* restrict d,
                                 __global const float* restrict depth, int W, int H, float ui, float vi,
                                 float dd, __global float* restrict out, const sf_method_params P,
                                 const sf_plane_params PP) {
  const sf_plane p = sf_receiver_plane_points(i, count, u, v, d, depth, W, H, ui, vi, dd, PP);
  out[i] = clamp(sf_esm_pcf2x2(depth, W, H, &p, sf_plane_bias(&p, 0.0f, PP), P.c), 0.0f, 1.0f);
}

// One receiver of the points kernels, every mode and lookup.
inline void sf_classify_one(__global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
                            __global const float* restrict sat, __global const float* restrict depth,
                            __global const float* restrict zbase, __global const float* restrict zchain,
                            int W, int H, __global const float* restrict u, __global const float* restrict v,
                            __global const float* restrict d, __global const float* restrict f,
                            __global float* restrict out, __global uchar* restrict flags, int count,
                            const sf_classify_params* C, const sf_method_params P, const sf_plane_params PP,
                            int i) {
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    flags[i] = 0;
    return;
  }
  const float fi = f ? f[i] : 1.0f;
  float b[SF_CHANNELS] = {0.0f};
  float zmax = 0.0f;
  if (C->mode == SF_CLASSIFY_THRESHOLD) sf_lookup(basis, chain, sat, W, H, ui, vi, fi, b);
  else zmax = sf_zmax_support(zbase ? zbase : depth, zchain, C, W, H, ui, vi, fi);
  const float dd = clamp(di, 0.0f, 1.0f);
  const bool flag = sf_classify(dd, zmax, b, *C, P);
  flags[i] = flag ? 1 : 0;
  if (flag) sf_classify_fallback(i, count, u, v, d, depth, W, H, ui, vi, dd, out, P, PP);
}

#define SF_CLASSIFY_POINTS_ARGS                                                                     \
  __global const sf_stored *restrict basis, __global const sf_stored *restrict chain,               \
      __global const float *restrict sat, __global const float *restrict depth,                     \
      __global const float *restrict zbase, __global const float *restrict zchain, const int W,     \
      const int H, __global const float *restrict u, __global const float *restrict v,              \
      __global const float *restrict d, __global const float *restrict f, __global float *restrict out, \
      __global uchar *restrict flags, const int count, const sf_classify_params C,                  \
      const sf_method_params P, const sf_plane_params PP

// One receiver per work-item: the threshold mode and the SAT's box.
__kernel void sf_esm_classify_points(SF_CLASSIFY_POINTS_ARGS) {
  const int i = get_global_id(0);
  if (i < count)
    sf_classify_one(basis, chain, sat, depth, zbase, zchain, W, H, u, v, d, f, out, flags, count, &C, P, PP, i);
}

#if SF_LOOKUP != SF_LOOKUP_SAT && SF_RX_VEC > 1
// Max of the 2x2 texels that level k's bilinear lookup at (u, v) weighs, lane by lane k: the
// coordinates as vectors (sf_rx_bilinear's), one load per texel and lane.
SF_RX_INLINE sf_rxf sf_rx_zmax_level(__global const float* restrict zbase, __global const float* restrict zchain,
                                    const sf_classify_params* C, int W, int H, sf_rxi k, sf_rxf u, sf_rxf v) {
  const sf_rxi one = (sf_rxi)(1), zero = (sf_rxi)(0);
  const sf_rxi w = (((sf_rxi)(W - 1)) >> k) + one, h = (((sf_rxi)(H - 1)) >> k) + one;
  const sf_rxi xi = sf_rx_floori(fma(u, sf_rx_float(w), -0.5f)), yi = sf_rx_floori(fma(v, sf_rx_float(h), -0.5f));
  const sf_rxi x0 = clamp(xi, zero, w - 1), x1 = clamp(xi + 1, zero, w - 1);
  const sf_rxi r0 = clamp(yi, zero, h - 1) * w, r1 = clamp(yi + 1, zero, h - 1) * w;
  sf_rxf m;
#pragma unroll
  for (int j = 0; j < SF_RX_VEC; ++j) {
    __global const float* z = k[j] == 0 ? zbase : zchain + C->zoff[k[j]];
    m[j] = fmax(fmax(z[r0[j] + x0[j]], z[r0[j] + x1[j]]), fmax(z[r1[j] + x0[j]], z[r1[j] + x1[j]]));
  }
  return m;
}

// zmax mode with the bilinear or trilinear lookup, SF_RX_VEC receivers per work-item (the
// reconstruction's vector form, lookup.clh): the flag test as vectors, which PoCL runs as SIMD,
// and the fall-back lane by lane for the flagged lanes only. The same flags and values as
// sf_esm_classify_points (test_classify.cpp); the host launches ceil(count / SF_RX_VEC) items.
__kernel void sf_esm_classify_points_vec(SF_CLASSIFY_POINTS_ARGS) {
  const int i0 = get_global_id(0) * SF_RX_VEC;
  if (i0 >= count) return;
  if (count - i0 < SF_RX_VEC) {
    for (int i = i0; i < count; ++i)
      sf_classify_one(basis, chain, sat, depth, zbase, zchain, W, H, u, v, d, f, out, flags, count, &C, P, PP, i);
    return;
  }
  const sf_rxf ui = sf_rx_vload(u + i0), vi = sf_rx_vload(v + i0), di = sf_rx_vload(d + i0);
  const sf_rxi inside = isfinite(di) & (ui >= 0.0f) & (ui <= 1.0f) & (vi >= 0.0f) & (vi <= 1.0f);
  if (!any(inside)) {
    SF_RX_CAT(vstore, SF_RX_VEC)((SF_RX_CAT(uchar, SF_RX_VEC))(0), 0, flags + i0);
    return;
  }
  const sf_rxf centre = (sf_rxf)(0.5f);
  const sf_rxf uc = select(centre, ui, inside), vc = select(centre, vi, inside);
  __global const float* zb = zbase ? zbase : depth;
  sf_rxi k0 = (sf_rxi)(0);
  sf_rxf t = (sf_rxf)(0.0f);
#if SF_LOOKUP == SF_LOOKUP_MIPS
  {  // sf_lod lane by lane: LOD = log2(max(f, 1)), non-finite f as 1, clamped to the top level
    const sf_rxf fv = f ? sf_rx_vload(f + i0) : (sf_rxf)(1.0f);
    const sf_rxf lod = log2(select((sf_rxf)(1.0f), fmax(fv, 1.0f), isfinite(fv)));
    const sf_rxf fl = floor(lod);
    k0 = sf_rx_int(fl);
    t = lod - fl;
    const sf_rxi past = k0 >= (sf_rxi)(C.top);
    k0 = select(k0, (sf_rxi)(C.top), past);
    t = select(t, (sf_rxf)(0.0f), past);
  }
#endif
  const sf_rxi between = t > 0.0f;
  const sf_rxi k1 = select(k0, k0 + 1, between);
  sf_rxf zmax = sf_rx_zmax_level(zb, zchain, &C, W, H, k1, uc, vc);
  // Trilinear between a finer level with an odd side and the coarser one: both (sf_zmax_support).
  const sf_rxi odd = between & (((((sf_rxi)(W - 1)) >> k0) + 1 | (((sf_rxi)(H - 1)) >> k0) + 1) & 1) != 0;
  if (any(odd)) zmax = select(zmax, fmax(zmax, sf_rx_zmax_level(zb, zchain, &C, W, H, k0, uc, vc)), odd);
  const sf_rxf dc = clamp(select(centre, di, inside), 0.0f, 1.0f);
  const sf_rxi flag = inside & (zmax > dc + C.offset);
  SF_RX_CAT(vstore, SF_RX_VEC)(SF_RX_CAT(convert_uchar, SF_RX_VEC)(flag & 1), 0, flags + i0);
  if (!any(flag)) return;
  for (int j = 0; j < SF_RX_VEC; ++j)
    if (flag[j]) sf_classify_fallback(i0 + j, count, u, v, d, depth, W, H, ui[j], vi[j], dc[j], out, P, PP);
}
#endif

// --receiver-depth mode: receivers at texel centres, footprint 1.
__kernel void sf_esm_classify_grid(
    __global const sf_stored* restrict basis, __global const sf_stored* restrict chain,
    __global const float* restrict sat, __global const float* restrict depth,
    __global const float* restrict zbase, __global const float* restrict zchain, const int W, const int H,
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
  float zmax = 0.0f;
  if (C.mode == SF_CLASSIFY_THRESHOLD) sf_lookup_texel(basis, W, W * H, x, y, b);  // as sf_reconstruct_grid reads it
  else zmax = (zbase ? zbase : depth)[i];  // the texel widened by R
  const float dd = clamp(di, 0.0f, 1.0f);
  const bool flag = sf_classify(dd, zmax, b, C, P);
  flags[i] = flag ? 1 : 0;
  if (flag) {
    const sf_plane p = sf_receiver_plane_grid(d, depth, W, H, x, y, dd, PP);
    out[i] = clamp(sf_esm_pcf2x2(depth, W, H, &p, sf_plane_bias(&p, 0.0f, PP), P.c), 0.0f, 1.0f);
  }
}
