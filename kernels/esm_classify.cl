// ESM failure classification and fall-back (Annen 2008 ch. 7.3; methods.md sec. 3; docs/lookups.md).
// Needs common.clh, storage.clh, methods/esm.clh, lookup.clh (SF_LOOKUP) and receiver_plane.clh
// before it. Runs after reconstruction: flagged receivers get a 2x2 PCF of the ESM test on the raw
// depth against their plane instead.
//
// Modes: 1 = zmax: flag when some depth texel in the lookup's support, widened by the blur's
// radius R, has z > d + offset. It reads the dilated z-max pyramid (classify.hpp,
// enqueue_zmax_pyramid): zbase = the depth max-filtered over (2R+1)^2 (clamped; the depth itself
// when R = 0), zchain its
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
  else zmax = sf_zmax_support(zbase, zchain, C, W, H, ui, vi, fi);
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

// One receiver per work-item: the SAT's box, and vector width 1.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_esm_classify_points)
__kernel void sf_esm_classify_points(SF_CLASSIFY_POINTS_ARGS) {
  const int i = get_global_id(0);
  if (i < count)
    sf_classify_one(basis, chain, sat, depth, zbase, zchain, W, H, u, v, d, f, out, flags, count, &C, P, PP, i);
}
#endif

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
  if (all(w >= 2)) {
    // Each row's two texels as one 8-byte load at px = min(x0, w - 2), as the reconstruction's
    // SF_RX_PAIRS: x0 and x1 are that pair's first or second value (the same texels, half the
    // loads). A level 1 texel wide has no second value in its row: lane by lane below.
    const sf_rxi px = min(x0, w - 2), a0 = r0 + px, a1 = r1 + px;
    SF_RX_CAT(ulong, SF_RX_VEC) q0, q1;
#pragma unroll
    for (int j = 0; j < SF_RX_VEC; ++j) {
      __global const float* z = k[j] == 0 ? zbase : zchain + C->zoff[k[j]];
      q0[j] = *(__global const sf_ulong_a4*)(z + a0[j]);
      q1[j] = *(__global const sf_ulong_a4*)(z + a1[j]);
    }
    const sf_rxf lo0 = sf_rx_as_float(SF_RX_CAT(convert_int, SF_RX_VEC)(q0));
    const sf_rxf hi0 = sf_rx_as_float(SF_RX_CAT(convert_int, SF_RX_VEC)(q0 >> 32));
    const sf_rxf lo1 = sf_rx_as_float(SF_RX_CAT(convert_int, SF_RX_VEC)(q1));
    const sf_rxf hi1 = sf_rx_as_float(SF_RX_CAT(convert_int, SF_RX_VEC)(q1 >> 32));
    const sf_rxi s0 = x0 != px, s1 = x1 != px;
    return fmax(fmax(select(lo0, hi0, s0), select(lo0, hi0, s1)), fmax(select(lo1, hi1, s0), select(lo1, hi1, s1)));
  }
#pragma unroll
  for (int j = 0; j < SF_RX_VEC; ++j) {
    __global const float* z = k[j] == 0 ? zbase : zchain + C->zoff[k[j]];
    m[j] = fmax(fmax(z[r0[j] + x0[j]], z[r0[j] + x1[j]]), fmax(z[r1[j] + x0[j]], z[r1[j] + x1[j]]));
  }
  return m;
}

// ---- The fall-back of SF_RX_VEC receivers (sf_receiver_plane_points and sf_esm_pcf2x2 as vectors).

// a[i0 + s + j] per lane j: one vector load where the window lies in [0, count), else lane by
// lane at clamped indices (lanes the caller's masks drop).
SF_RX_INLINE sf_rxf sf_rx_shifted(__global const float* restrict a, int i0, int s, int count) {
  const int lo = i0 + s;
  if (lo >= 0 && lo + SF_RX_VEC <= count) return sf_rx_vload(a + lo);
  sf_rxf r;
#pragma unroll
  for (int j = 0; j < SF_RX_VEC; ++j) r[j] = a[sf_clampi(lo + j, 0, count - 1)];
  return r;
}

// The neighbours at i - step (a) and i + step (b) of every lane, where has_lo / has_hi, as
// sf_plane_axis: the central step where both exist and agree, else the smaller one. Returns the
// lanes with a step; e = (x, y, depth) step in texels.
SF_RX_INLINE sf_rxi sf_rx_plane_axis(int i0, int step, sf_rxi has_lo, sf_rxi has_hi, __global const float* restrict u,
                                     __global const float* restrict v, __global const float* restrict d, int count,
                                     int W, int H, sf_rxf ui, sf_rxf vi, sf_rxf di, sf_rxf* ex, sf_rxf* ey,
                                     sf_rxf* ez) {
  const sf_rxf ua = sf_rx_shifted(u, i0, -step, count), va = sf_rx_shifted(v, i0, -step, count),
               da = sf_rx_shifted(d, i0, -step, count);
  const sf_rxf ub = sf_rx_shifted(u, i0, step, count), vb = sf_rx_shifted(v, i0, step, count),
               db = sf_rx_shifted(d, i0, step, count);
  const sf_rxi a = has_lo & sf_rx_inside(ua, va, da), b = has_hi & sf_rx_inside(ub, vb, db);
  const sf_rxf ax = (ua - ui) * (float)W, ay = (va - vi) * (float)H, ad = da - di;
  const sf_rxf bx = (ub - ui) * (float)W, by = (vb - vi) * (float)H, bd = db - di;
  const sf_rxf la = sqrt(fma(ax, ax, ay * ay)), lb = sqrt(fma(bx, bx, by * by));
  const sf_rxf sa = -ad / la, sb = bd / lb;
  const sf_rxi central = a & b & (la > 0.0f) & (lb > 0.0f) & (fabs(sb - sa) <= 0.5f * fmax(fabs(sa), fabs(sb)));
  const sf_rxi use_a = ~central & a & (~b | (fabs(ad) <= fabs(bd)));
  const sf_rxi use_b = ~central & ~use_a & b;
  *ex = select(select(select((sf_rxf)(0.0f), bx, use_b), ax, use_a), bx - ax, central);
  *ey = select(select(select((sf_rxf)(0.0f), by, use_b), ay, use_a), by - ay, central);
  *ez = select(select(select((sf_rxf)(0.0f), bd, use_b), ad, use_a), bd - ad, central);
  return central | use_a | use_b;
}

// The 2x2 PCF of every lane against its plane (sf_esm_pcf2x2), one load per texel and lane.
SF_RX_INLINE sf_rxf sf_rx_esm_pcf2x2(__global const float* restrict depth, int W, int H, sf_rxf px, sf_rxf py,
                                     sf_rxf pd, sf_rxf gx, sf_rxf gy, sf_rxf bias, float c) {
  const sf_rxf xf = floor(px), yf = floor(py), ax = px - xf, ay = py - yf;
  const sf_rxi zero = (sf_rxi)(0), xi = sf_rx_int(xf), yi = sf_rx_int(yf);
  const sf_rxi x0 = clamp(xi, zero, (sf_rxi)(W - 1)), x1 = clamp(xi + 1, zero, (sf_rxi)(W - 1));
  const sf_rxi y0 = clamp(yi, zero, (sf_rxi)(H - 1)), y1 = clamp(yi + 1, zero, (sf_rxi)(H - 1));
  sf_rxf z00, z10, z01, z11;
  if (W >= 2) {  // each row's two texels as one 8-byte load, as in sf_rx_zmax_level
    const sf_rxi px = min(x0, (sf_rxi)(W - 2)), s0 = x0 != px, s1 = x1 != px;
    sf_rxf lo0, hi0, lo1, hi1;
    sf_rx_pair(depth, y0 * W + px, &lo0, &hi0);
    sf_rx_pair(depth, y1 * W + px, &lo1, &hi1);
    z00 = select(lo0, hi0, s0), z10 = select(lo0, hi0, s1);
    z01 = select(lo1, hi1, s0), z11 = select(lo1, hi1, s1);
  } else {
#pragma unroll
    for (int j = 0; j < SF_RX_VEC; ++j) {
      z00[j] = depth[y0[j] * W + x0[j]], z10[j] = depth[y0[j] * W + x1[j]];
      z01[j] = depth[y1[j] * W + x0[j]], z11[j] = depth[y1[j] * W + x1[j]];
    }
  }
#define SF_RX_T(Z, X, Y) \
  exp(fmin(c * (Z - fma(gx, sf_rx_float(X) - px, fma(gy, sf_rx_float(Y) - py, pd)) + bias), 0.0f))
  return mix(mix(SF_RX_T(z00, x0, y0), SF_RX_T(z10, x1, y0), ax), mix(SF_RX_T(z01, x0, y1), SF_RX_T(z11, x1, y1), ax),
             ay);
#undef SF_RX_T
}

// Rewrites out[i0 ..] where `flag`: each flagged lane's plane (sf_receiver_plane_points: from its
// image neighbours, else the depth map's slope lane by lane) and its 2x2 PCF.
SF_RX_INLINE void sf_rx_classify_fallback(int i0, sf_rxi flag, int count, __global const float* restrict u,
                                          __global const float* restrict v, __global const float* restrict d,
                                          __global const float* restrict depth, int W, int H, sf_rxf ui, sf_rxf vi,
                                          sf_rxf dd, __global float* restrict out, const sf_method_params P,
                                          const sf_plane_params PP) {
  const sf_rxf px = fma(ui, (float)W, -0.5f), py = fma(vi, (float)H, -0.5f);
  sf_rxf gx = (sf_rxf)(0.0f), gy = gx;
  if (PP.on) {
    sf_rxi solved = (sf_rxi)(0);
    if (PP.row > 0) {
      sf_rxi idx;
#pragma unroll
      for (int j = 0; j < SF_RX_VEC; ++j) idx[j] = i0 + j;
      const sf_rxi col = idx % PP.row, n = (sf_rxi)(count);
      sf_rxf a0, a1, a2, b0, b1, b2;
      const sf_rxi ha = sf_rx_plane_axis(i0, 1, col > 0, (col + 1 < PP.row) & (idx + 1 < n), u, v, d, count, W, H, ui,
                                         vi, dd, &a0, &a1, &a2);
      const sf_rxi hb = sf_rx_plane_axis(i0, PP.row, idx >= PP.row, idx + PP.row < n, u, v, d, count, W, H, ui, vi,
                                         dd, &b0, &b1, &b2);
      const sf_rxf det = a0 * b1 - a1 * b0;
      const sf_rxf la = sqrt(fma(a0, a0, a1 * a1)), lb = sqrt(fma(b0, b0, b1 * b1));
      gx = (a2 * b1 - b2 * a1) / det;
      gy = (a0 * b2 - b0 * a2) / det;
      solved = ha & hb & (fabs(det) > 1e-3f * la * lb) & (la > 0.0f) & (lb > 0.0f) & isfinite(gx) & isfinite(gy);
    }
    if (any(flag & ~solved)) {
      for (int j = 0; j < SF_RX_VEC; ++j)
        if (flag[j] && !solved[j]) {
          float sx, sy;
          sf_image_slope(depth, W, H, (int)floor(px[j] + 0.5f), (int)floor(py[j] + 0.5f), &sx, &sy);
          gx[j] = sx, gy[j] = sy;
        }
    }
    gx = select((sf_rxf)(0.0f), clamp(gx, -PP.max_slope, PP.max_slope), isfinite(gx));
    gy = select((sf_rxf)(0.0f), clamp(gy, -PP.max_slope, PP.max_slope), isfinite(gy));
  }
  const sf_rxf bias = fma((sf_rxf)(PP.slope_bias), fabs(gx) + fabs(gy), 0.0f);
  const sf_rxf vis = clamp(sf_rx_esm_pcf2x2(depth, W, H, px, py, dd, gx, gy, bias, P.c), 0.0f, 1.0f);
  sf_rx_vstore(select(sf_rx_vload(out + i0), vis, flag), out + i0);
}

// Both modes with the bilinear or trilinear lookup, SF_RX_VEC receivers per work-item (the
// reconstruction's vector form, lookup.clh): the flag test (zmax: the dilated pyramid's 2x2;
// threshold: the filtered basis) and, where a lane is flagged, the
// fall-back as vectors, which PoCL runs as SIMD (in one receiver per work-item both ran lane by
// lane: PoCL does not vectorise their branches across work-items). The same flags and values as
// sf_esm_classify_points within float rounding (test_classify.cpp); the host launches
// ceil(count / SF_RX_VEC) items.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_esm_classify_points_vec)
__kernel void sf_esm_classify_points_vec(SF_CLASSIFY_POINTS_ARGS) {
  const int i0 = get_global_id(0) * SF_RX_VEC;
  if (i0 >= count) return;
  if (count - i0 < SF_RX_VEC) {
    for (int i = i0; i < count; ++i)
      sf_classify_one(basis, chain, sat, depth, zbase, zchain, W, H, u, v, d, f, out, flags, count, &C, P, PP, i);
    return;
  }
  const sf_rxf ui = sf_rx_vload(u + i0), vi = sf_rx_vload(v + i0), di = sf_rx_vload(d + i0);
  const sf_rxi inside = sf_rx_inside(ui, vi, di);
  if (!any(inside)) {
    SF_RX_CAT(vstore, SF_RX_VEC)((SF_RX_CAT(uchar, SF_RX_VEC))(0), 0, flags + i0);
    return;
  }
  const sf_rxf centre = (sf_rxf)(0.5f);
  const sf_rxf uc = select(centre, ui, inside), vc = select(centre, vi, inside);
  const sf_rxf dc = clamp(select(centre, di, inside), 0.0f, 1.0f);
  sf_rxi flag;
  if (C.mode == SF_CLASSIFY_THRESHOLD) {
    // The filtered basis as the reconstruction read it (sf_rx_lookup over the separate level 0
    // and chain: the classification is built without SF_MIPS_JOINED), then sf_classify's test.
    sf_rxf b[SF_CHANNELS];
    sf_rx_lookup(basis, chain, sat, (__constant int*)0, W, H, uc, vc, f ? sf_rx_vload(f + i0) : (sf_rxf)(1.0f), b);
    flag = inside & (log(fmax(b[0], FLT_MIN)) - P.c * (dc - 0.5f) > C.log_thresh);
  } else {
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
    sf_rxf zmax = sf_rx_zmax_level(zbase, zchain, &C, W, H, k1, uc, vc);
    // Trilinear between a finer level with an odd side and the coarser one: both (sf_zmax_support).
    const sf_rxi odd = between & (((((sf_rxi)(W - 1)) >> k0) + 1 | (((sf_rxi)(H - 1)) >> k0) + 1) & 1) != 0;
    if (any(odd)) zmax = select(zmax, fmax(zmax, sf_rx_zmax_level(zbase, zchain, &C, W, H, k0, uc, vc)), odd);
    flag = inside & (zmax > dc + C.offset);
  }
  SF_RX_CAT(vstore, SF_RX_VEC)(SF_RX_CAT(convert_uchar, SF_RX_VEC)(flag & 1), 0, flags + i0);
  if (any(flag)) sf_rx_classify_fallback(i0, flag, count, u, v, d, depth, W, H, uc, vc, dc, out, P, PP);
}
#endif
#endif

// --receiver-depth mode: receivers at texel centres, footprint 1.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_esm_classify_grid)
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
  else zmax = zbase[i];  // the texel widened by R
  const float dd = clamp(di, 0.0f, 1.0f);
  const bool flag = sf_classify(dd, zmax, b, C, P);
  flags[i] = flag ? 1 : 0;
  if (flag) {
    const sf_plane p = sf_receiver_plane_grid(d, depth, W, H, x, y, dd, PP);
    out[i] = clamp(sf_esm_pcf2x2(depth, W, H, &p, sf_plane_bias(&p, 0.0f, PP), P.c), 0.0f, 1.0f);
  }
}
#endif
