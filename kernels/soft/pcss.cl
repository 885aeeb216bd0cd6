// pcss (Fernando 2005; methods.md sec. 4, seed 003 eq. 2.1/3.1): brute force on the raw depth.
// Needs common.clh and soft/soft_common.clh before it.
// 1. blocker search: area-weighted box of width w(d, z = 0) (the light's footprint at the near
//    plane: the widest any blocker can make it), mean z of the texels with z < d - bias;
// 2. PCF: area-weighted box of width w(d, z_avg) (at least the receiver footprint f and one
//    texel) of the test z >= d - bias. No blocker found: lit (1).
// Cost grows with the light size (widths in texels squared).
__kernel void sf_pcss_points(__global const float* restrict depth, const int W, const int H,
                             __global const float* restrict u, __global const float* restrict v,
                             __global const float* restrict d, __global const float* restrict f,
                             __global float* restrict out, const int count, const sf_soft_light L) {
  const int i = get_global_id(0);
  float ui, vi, di;
  if (!sf_receiver_fetch(i, count, u, v, d, out, &ui, &vi, &di)) return;
  const float dd = clamp(di, 0.0f, 1.0f);
  const float fp = f ? (isfinite(f[i]) ? f[i] : 1.0f) : 1.0f;
  const float cx = ui * (float)W, cy = vi * (float)H;
  const float search = clamp(sf_soft_width(L, dd, 0.0f) * (float)W, 1.0f, L.max_width);
  const float sy = (float)H / (float)W;  // uv widths map to W texels in x, H in y
  const sf_box_acc s = sf_box_scan(depth, W, H, cx, cy, 0.5f * search, 0.5f * search * sy, dd, L.bias);
  if (!(s.blk > 0.0f)) {
    out[i] = 1.0f;
    return;
  }
  const float zavg = s.blkz / s.blk;
  const float width = clamp(fmax(sf_soft_width(L, dd, zavg) * (float)W, fp), 1.0f, L.max_width);
  const sf_box_acc p = sf_box_scan(depth, W, H, cx, cy, 0.5f * width, 0.5f * width * sy, dd, L.bias);
  out[i] = clamp(p.lit / p.w, 0.0f, 1.0f);
}
