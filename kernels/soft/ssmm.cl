// ssmm: soft shadow mip-maps (Shen 2016; methods.md sec. 4). Needs common.clh, receiver_plane.clh
// and soft/soft_common.clh before it. Reads the raw depth (level 0) and its min-depth pyramid
// (pyramid.cl, Reduce::Min; levels 1.. in `chain`, one plane each). Every texel is tested against
// the receiver's plane as its level sees it (sf_plane_level: the plane's minimum over the texel's
// block), with the bias b (the light's constant plus the plane's slope-scaled term); "z < d -
// bias" below reads so. The result is times the fraction of the light above the receiver's
// horizon (sf_soft_horizon).
// Layer i (level i of the pyramid, w_i texels wide) filters an area-weighted n x n box
// (Shen 2016 sec. 3.4): its filter width in uv units is r_i = n / w_i (eq. 3.4, h_i = 1 / w_i).
// Filter size of a blocker at z for a receiver at d: r = w(d, z) (eq. 3.3; soft_common.clh). A
// rectangular light's r is a size between its footprint's sides (sf_soft_scale: ssmm the shorter,
// at least the longer / 8; ssmm-improved at least the longer / 1.5), and its boxes have its
// shape: n texels along the side r measures, n times the ratio of the sides along the other
// (sf_soft_shape); a square light's are n x n.
//   mode 0 (ssmm): z_avg from a blocker search on the layer whose n x n box covers the search
//     width w(d, 0) (constant cost), r = w(d, z_avg); layers a, b = a + 1 with r_a <= r < r_b,
//     S = w_a S_a + w_b S_b, w_b = (r - r_a) / (r_b - r_a), w_a = 1 - w_b (eqs. 3.8-3.10).
//     r < r_0: layer 0 with a box of max(r W, f, 1) texels; r >= r_top: the top layer.
//   mode 1 (ssmm-improved, eqs. 3.11-3.17): every texel j of layer i's box that blocks
//     (z_ij < d - bias) has its own r_ij = w(d, z_ij) and obscures f_j w_ij of the light, with the
//     hat weight w_ij = (r_ij - r_{i-1}) / (r_i - r_{i-1}) for r_{i-1} <= r_ij <= r_i,
//     (r_{i+1} - r_ij) / (r_{i+1} - r_i) for r_i < r_ij < r_{i+1}, else 0 (eq. 3.11, with
//     r_{i+1} = 2 r_i); layer 0 takes weight 1 below r_0 (eq. 3.12), the top layer 1 above
//     r_top (eq. 3.13); v = 1 - sum_i sum_j f_j w_ij (eqs. 3.15-3.17).

inline __global const float* sf_ssmm_level(__global const float* depth, __global const float* chain,
                                           int W, int H, int k, int* w, int* h) {
  if (k == 0) {
    *w = W;
    *h = H;
    return depth;
  }
  size_t off;
  sf_mip_level(W, H, 1, k, w, h, &off);
  return chain + off;
}

__kernel void sf_ssmm_points(__global const float* restrict depth, __global const float* restrict chain,
                             const int W, const int H, __global const float* restrict u,
                             __global const float* restrict v, __global const float* restrict d,
                             __global const float* restrict f, __global float* restrict out,
                             const int count, const sf_soft_light L, const int n, const int mode,
                             const sf_plane_params P) {
  const int i = get_global_id(0);
  float ui, vi, di;
  if (!sf_receiver_fetch(i, count, u, v, d, out, &ui, &vi, &di)) return;
  const float dd = clamp(di, 0.0f, 1.0f);
  const sf_plane p0 = sf_receiver_plane_points(i, count, u, v, d, depth, W, H, ui, vi, dd, P);
  const float bias = sf_plane_bias(&p0, L.bias, P);
  const float horizon = sf_soft_horizon(L, &p0, W, H);  // as pcss
  const float2 fp = sf_soft_footprint(f, count, i);
  const int top = sf_mip_top(W, H);
  const float nf = (float)n;
  const float2 search2 = sf_soft_width(L, dd, 0.0f);  // uv units
  const float aniso = mode == 1 ? SF_SSMM_IMPROVED_ANISO : SF_SOFT_MAX_ANISO;
  const float search = sf_soft_scale(L, dd, 0.0f, aniso);
  const float2 shape = sf_soft_shape(L, aniso);
  const float bx = 0.5f * nf * shape.x, by = 0.5f * nf * shape.y;  // a layer's box, half sides (texels of x)
  // Highest layer whose box can matter: r_i < 2 * search (r_{i-1} <= search).
  int last = 0;
  while (last < top && nf * (float)(1 << last) / (float)W < search) ++last;
  int w, h;
  if (mode == 1) {
    float sb = 0.0f;
    for (int k = 0; k <= last; ++k) {
      __global const float* img = sf_ssmm_level(depth, chain, W, H, k, &w, &h);
      const sf_plane pk = sf_plane_level(&p0, W, H, w, h);
      const float ri = nf / (float)w, rlo = 0.5f * ri, rhi = 2.0f * ri;
      const float cx = ui * (float)w, cy = vi * (float)h, hx = bx, hy = by * (float)h / (float)w;
      const float x0 = cx - hx, x1 = cx + hx, y0 = cy - hy, y1 = cy + hy;
      const int i0 = (int)floor(x0), i1 = (int)ceil(x1) - 1, j0 = (int)floor(y0), j1 = (int)ceil(y1) - 1;
      float acc = 0.0f, wsum = 0.0f;
      for (int j = j0; j <= j1; ++j) {
        const float wy = fmin(y1, (float)(j + 1)) - fmax(y0, (float)j);
        if (wy <= 0.0f) continue;
        const int tj = sf_clampi(j, 0, h - 1);
        __global const float* row = img + (size_t)tj * w;
        const float row_d = fma(pk.gy, (float)tj - pk.y, pk.d) - bias;
        for (int x = i0; x <= i1; ++x) {
          const float wx = fmin(x1, (float)(x + 1)) - fmax(x0, (float)x);
          if (wx <= 0.0f) continue;
          wsum += wx * wy;
          const int tx = sf_clampi(x, 0, w - 1);
          const float z = row[tx];
          if (!(z < fma(pk.gx, (float)tx - pk.x, row_d))) continue;
          const float r = sf_soft_scale(L, dd, z, aniso);
          float wt;
          if (r <= ri)
            wt = (k == 0) ? 1.0f : fmax((r - rlo) / (ri - rlo), 0.0f);
          else
            wt = (k == top) ? 1.0f : fmax((rhi - r) / (rhi - ri), 0.0f);
          acc = fma(wx * wy, wt, acc);
        }
      }
      sb += acc / wsum;
    }
    out[i] = clamp(1.0f - sb, 0.0f, 1.0f) * horizon;
    return;
  }
  // mode 0: blocker search on layer `last` (its n x n box covers the search width).
  __global const float* img = sf_ssmm_level(depth, chain, W, H, last, &w, &h);
  const float swx = fmax(search2.x * (float)w, 1.0f), swy = fmax(search2.y * (float)h, 1.0f);
  sf_plane pk = sf_plane_level(&p0, W, H, w, h);
  sf_box_acc s = sf_box_scan(img, w, h, ui * (float)w, vi * (float)h, 0.5f * swx, 0.5f * swy, &pk, bias);
  if (!(s.blk > 0.0f)) {
    out[i] = horizon;
    return;
  }
  const float2 r2 = sf_soft_width(L, dd, s.blkz / s.blk);
  const float r = sf_soft_scale(L, dd, s.blkz / s.blk, aniso);
  const float r0 = nf / (float)W;
  if (r < r0) {
    // At most layer 0's box (n texels times the light's shape), at least one texel.
    const float2 cap = fmax((float2)(2.0f * bx, 2.0f * by * (float)H / (float)W), 1.0f);
    const float2 width = clamp(fmax((float2)(r2.x * (float)W, r2.y * (float)H), fp), 1.0f, cap);
    s = sf_box_scan(depth, W, H, ui * (float)W, vi * (float)H, 0.5f * width.x, 0.5f * width.y, &p0, bias);
    out[i] = clamp(s.lit / s.w, 0.0f, 1.0f) * horizon;
    return;
  }
  int a = (int)floor(log2(r / r0));
  a = min(a, top);
  float res = 0.0f;
  const float ra = r0 * (float)(1 << a);
  const float wb = a >= top ? 0.0f : clamp((r - ra) / ra, 0.0f, 1.0f);
  for (int t = 0; t < 2; ++t) {
    const int k = a + t;
    const float wt = t == 0 ? 1.0f - wb : wb;
    if (wt <= 0.0f) continue;
    img = sf_ssmm_level(depth, chain, W, H, k, &w, &h);
    pk = sf_plane_level(&p0, W, H, w, h);
    s = sf_box_scan(img, w, h, ui * (float)w, vi * (float)h, bx, by * (float)h / (float)w, &pk, bias);
    res = fma(wt, s.lit / s.w, res);
  }
  out[i] = clamp(res, 0.0f, 1.0f) * horizon;
}
