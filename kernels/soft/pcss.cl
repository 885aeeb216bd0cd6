// pcss (Fernando 2005; methods.md sec. 4, Shen 2016 eq. 2.1/3.1): brute force on the raw depth.
// Needs common.clh, receiver_plane.clh and soft/soft_common.clh before it.
// Every texel t is tested against the receiver's plane d_t (receiver_plane.clh) with the bias b
// (the light's constant plus the plane's slope-scaled term):
// 1. blocker search: area-weighted box of the light's footprint w(d, z = 0) (at the near plane:
//    the widest any blocker can make it), mean z of the texels with z < d_t - b;
// 2. PCF: area-weighted box of the footprint w(d, z_avg) (each side at least the receiver
//    footprint f and one texel) of the test z >= d_t - b. No blocker found: lit (1).
// Both boxes are the light's rectangle (sf_soft_width: its two sides).
// Times the fraction of the light above the receiver's own horizon (sf_soft_horizon), which the
// plane's test leaves out.
// Cost grows with the light size (widths in texels squared).
__kernel void sf_pcss_points(__global const float* restrict depth, const int W, const int H,
                             __global const float* restrict u, __global const float* restrict v,
                             __global const float* restrict d, __global const float* restrict f,
                             __global float* restrict out, const int count, const sf_soft_light L,
                             const sf_plane_params P) {
  const int i = get_global_id(0);
  float ui, vi, di;
  if (!sf_receiver_fetch(i, count, u, v, d, out, &ui, &vi, &di)) return;
  const float dd = clamp(di, 0.0f, 1.0f);
  const sf_plane p = sf_receiver_plane_points(i, count, u, v, d, depth, W, H, ui, vi, dd, P);
  const float bias = sf_plane_bias(&p, L.bias, P);
  const float horizon = sf_soft_horizon(L, &p, W, H);
  const float2 fp = sf_soft_footprint(f, count, i);
  const float cx = ui * (float)W, cy = vi * (float)H;
  const float2 search = sf_soft_texels(L, sf_soft_width(L, dd, 0.0f), W, H, (float2)(1.0f));
  const sf_box_acc s = sf_box_scan(depth, W, H, cx, cy, 0.5f * search.x, 0.5f * search.y, &p, bias);
  if (!(s.blk > 0.0f)) {
    out[i] = horizon;
    return;
  }
  const float zavg = s.blkz / s.blk;
  const float2 width = sf_soft_texels(L, sf_soft_width(L, dd, zavg), W, H, fp);
  const sf_box_acc q = sf_box_scan(depth, W, H, cx, cy, 0.5f * width.x, 0.5f * width.y, &p, bias);
  out[i] = clamp(q.lit / q.w, 0.0f, 1.0f) * horizon;
}
