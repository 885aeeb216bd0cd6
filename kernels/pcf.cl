// sm and pcf: the shadow test evaluated per depth texel, then weighted (methods.md sec. 2-3):
//   v = sum_t W_x(t) H(z_t - d_t + bias)
// with W_x the composite Gaussian (x) bilinear weights of the prefilter lookup (sm: radius 0,
// the bilinear weights alone) and d_t the receiver's depth at texel t: its plane
// (receiver_plane.clh), or d itself with the plane off. The bias is the constant plus the
// plane's slope-scaled term (sf_plane_bias). Needs common.clh and
// receiver_plane.clh before it. Reads the raw float32 depth map.
//
// Both factors are separable and so are the clamp-to-edge rules, so W_x(t) = wx(i) wy(j) over
// a (2R+2)^2 window: with the bilinear taps x0 <= x1 (clamped, x1 - x0 = dx in {0, 1}) and
// the Gaussian g, the texel x0 + o gets wx = (1 - ax) g(o) + ax g(o - dx) (g = 0 beyond R),
// exactly the weight the blur-then-bilinear path gives it, so brute force costs (2R+2)^2 tests.

// sf_pcf_weights and SF_PCF_MAX_RADIUS: shared_types.clh.

inline float sf_pcf_g(const sf_pcf_weights* g, int radius, int o) {
  o = abs(o);
  return o <= radius ? g->w[o] : 0.0f;
}

// The receiver at texel-space (p->x, p->y) = (u W - 1/2, v H - 1/2), as in sf_lookup_bilinear.
inline float sf_pcf(__global const float* restrict depth, int width, int height, const sf_plane* p,
                    float bias, int radius, const sf_pcf_weights* g) {
  const float x = p->x, y = p->y;
  const float xf = floor(x), yf = floor(y);
  const float ax = x - xf, ay = y - yf;
  const int x0 = sf_clampi((int)xf, 0, width - 1), x1 = sf_clampi((int)xf + 1, 0, width - 1);
  const int y0 = sf_clampi((int)yf, 0, height - 1), y1 = sf_clampi((int)yf + 1, 0, height - 1);
  const int dx = x1 - x0, dy = y1 - y0;
  float acc = 0.0f;
  for (int oy = -radius; oy <= radius + 1; ++oy) {
    const float wy = (1.0f - ay) * sf_pcf_g(g, radius, oy) + ay * sf_pcf_g(g, radius, oy - dy);
    if (wy == 0.0f) continue;
    const int ty = sf_clampi(y0 + oy, 0, height - 1);
    __global const float* row = depth + (size_t)ty * width;
    const float row_d = fma(p->gy, (float)ty - y, p->d);  // the plane along this row
    float racc = 0.0f;
    for (int ox = -radius; ox <= radius + 1; ++ox) {
      const float wx = (1.0f - ax) * sf_pcf_g(g, radius, ox) + ax * sf_pcf_g(g, radius, ox - dx);
      const int tx = sf_clampi(x0 + ox, 0, width - 1);
      const float z = row[tx];
      racc += (z - fma(p->gx, (float)tx - x, row_d)) + bias >= 0.0f ? wx : 0.0f;
    }
    acc = fma(wy, racc, acc);
  }
  return clamp(acc, 0.0f, 1.0f);
}

// ---- Footprints (--lookup mips|sat; docs/lookups.md): the depth test under the same composite
// weights s_ref uses, brute force over level-0 texels. The weights are separable per lookup
// term: trilinear = (1 - t) A_x A_y + t B_x B_y (levels k0 and k0 + 1), box = A_x A_y. A 1-D
// term before the Gaussian is either a level-k bilinear pair pushed down the pyramid (level-k
// texel i covers level-0 texels t with t >> k == i, each with weight 2^-k, doubled at every
// level where t's ancestor is the clamped odd edge) or the box coverage; the Gaussian then
// spreads it with clamp-to-edge (all offsets that clamp onto an edge texel land on it).
#ifdef SF_LOOKUP
typedef struct {
  int box;      // 1: box [X0, X1) in texel space; 0: level-k taps i0, i1 with weights 1 - a, a
  int k, i0, i1;
  float a, X0, X1;
} sf_pcf_axis;

inline sf_pcf_axis sf_pcf_level_axis(float u, int n, int k) {
  sf_pcf_axis A;
  const int nk = ((n - 1) >> k) + 1;  // ceil(n / 2^k)
  const float x = fma(u, (float)nk, -0.5f), xf = floor(x);  // as sf_lookup_bilinear
  A.box = 0;
  A.k = k;
  A.a = x - xf;
  A.i0 = sf_clampi((int)xf, 0, nk - 1);
  A.i1 = sf_clampi((int)xf + 1, 0, nk - 1);
  A.X0 = (float)(min(A.i0, A.i1) << k);
  A.X1 = (float)min((max(A.i0, A.i1) + 1) << k, n);
  return A;
}

// Weight of level-0 texel t under level-k texel i (mip pushed down, odd edges clamped).
inline float sf_pcf_push(int t, int n, int k, int i) {
  if ((t >> k) != i) return 0.0f;
  float w = 1.0f;
  for (int j = 1; j <= k; ++j)
    if (2 * (t >> j) + 1 < ((n - 1) >> (j - 1)) + 1) w *= 0.5f;
  return w;
}

// Weight of level-0 texel t (in [0, n)) before the Gaussian.
inline float sf_pcf_pre(const sf_pcf_axis* A, int n, int t) {
  if (A->box) {
    const float lo = t == 0 ? -INFINITY : (float)t, hi = t == n - 1 ? INFINITY : (float)(t + 1);
    return fmax(0.0f, fmin(hi, A->X1) - fmax(lo, A->X0)) / (A->X1 - A->X0);
  }
  return (1.0f - A->a) * sf_pcf_push(t, n, A->k, A->i0) + A->a * sf_pcf_push(t, n, A->k, A->i1);
}

// Composite weight of level-0 texel s: the pre-blur weights spread by g with clamp-to-edge.
inline float sf_pcf_axis_weight(const sf_pcf_axis* A, int n, int s, int radius, const sf_pcf_weights* g) {
  float w = 0.0f;
  for (int a = -radius; a <= radius; ++a) {
    const int lo = max(s == 0 ? 0 : s - a, 0), hi = min(s == n - 1 ? n - 1 : s - a, n - 1);
    float acc = 0.0f;
    for (int t = lo; t <= hi; ++t) acc += sf_pcf_pre(A, n, t);
    w = fma(g->w[abs(a)], acc, w);
  }
  return w;
}

// Level-0 texels with a non-zero weight: the pre-blur support clamped into the map (a box wholly
// past an edge, which an anisotropic probe can be, weighs the edge texel), widened by R, clamped.
inline void sf_pcf_span(const sf_pcf_axis* A, int n, int radius, int* lo, int* hi) {
  *lo = max(min((int)floor(A->X0), n - 1) - radius, 0);
  *hi = min(max((int)ceil(A->X1) - 1, 0) + radius, n - 1);
}

#define SF_PCF_CHUNK 32

// The filtered test under a footprint lookup at (u, v): mips at footprint f, the box over fx x fy
// texels (as sf_lookup_rect).
inline float sf_pcf_footprint(__global const float* restrict depth, int W, int H, float u, float v,
                              float f, float fx, float fy, const sf_plane* p, float bias, int radius,
                              const sf_pcf_weights* g) {
  sf_pcf_axis ax[2], ay[2];
  float t = 0.0f;
#if SF_LOOKUP == SF_LOOKUP_MIPS
  const int k0 = sf_lod(f, sf_mip_top(W, H), &t);
  ax[0] = sf_pcf_level_axis(u, W, k0);
  ay[0] = sf_pcf_level_axis(v, H, k0);
  ax[1] = sf_pcf_level_axis(u, W, k0 + (t > 0.0f));
  ay[1] = sf_pcf_level_axis(v, H, k0 + (t > 0.0f));
#else
  const float sx = 0.5f * (isfinite(fx) ? fmax(fx, 1.0f) : 1.0f);  // as sf_lookup_rect
  const float sy = 0.5f * (isfinite(fy) ? fmax(fy, 1.0f) : 1.0f);
  ax[0].box = ay[0].box = 1;
  ax[0].X0 = fma(u, (float)W, -sx);
  ax[0].X1 = fma(u, (float)W, sx);
  ay[0].X0 = fma(v, (float)H, -sy);
  ay[0].X1 = fma(v, (float)H, sy);
  ax[1] = ax[0];
  ay[1] = ay[0];
#endif
  int xlo, xhi, ylo, yhi, l1, h1;
  sf_pcf_span(&ax[0], W, radius, &xlo, &xhi);
  sf_pcf_span(&ax[1], W, radius, &l1, &h1);
  xlo = min(xlo, l1);
  xhi = max(xhi, h1);
  sf_pcf_span(&ay[0], H, radius, &ylo, &yhi);
  sf_pcf_span(&ay[1], H, radius, &l1, &h1);
  ylo = min(ylo, l1);
  yhi = max(yhi, h1);
  const float wa = 1.0f - t, wb = t;
  float acc = 0.0f;
  for (int xc = xlo; xc <= xhi; xc += SF_PCF_CHUNK) {
    const int nc = min(SF_PCF_CHUNK, xhi - xc + 1);
    float cx0[SF_PCF_CHUNK], cx1[SF_PCF_CHUNK];
    for (int i = 0; i < nc; ++i) {
      cx0[i] = sf_pcf_axis_weight(&ax[0], W, xc + i, radius, g);
      cx1[i] = wb > 0.0f ? sf_pcf_axis_weight(&ax[1], W, xc + i, radius, g) : 0.0f;
    }
    for (int y = ylo; y <= yhi; ++y) {
      const float wy0 = wa * sf_pcf_axis_weight(&ay[0], H, y, radius, g);
      const float wy1 = wb > 0.0f ? wb * sf_pcf_axis_weight(&ay[1], H, y, radius, g) : 0.0f;
      if (wy0 == 0.0f && wy1 == 0.0f) continue;
      __global const float* row = depth + (size_t)y * W + xc;
      const float row_d = fma(p->gy, (float)y - p->y, p->d);
      float r0 = 0.0f, r1 = 0.0f;
      for (int i = 0; i < nc; ++i) {
        const bool lit = (row[i] - fma(p->gx, (float)(xc + i) - p->x, row_d)) + bias >= 0.0f;
        r0 += lit ? cx0[i] : 0.0f;
        r1 += lit ? cx1[i] : 0.0f;
      }
      acc = fma(wy0, r0, fma(wy1, r1, acc));
    }
  }
  return clamp(acc, 0.0f, 1.0f);
}

// Receivers with footprints f (null = 1 everywhere). SF_ANISO: f holds their Jacobians, four
// planes of count floats (lookup.clh "Anisotropic footprints"), and the test is the mean of the
// probes' tests, each against the receiver's own plane.
__kernel void sf_pcf_points_footprint(__global const float* restrict depth, const int width,
                                      const int height, __global const float* restrict u,
                                      __global const float* restrict v,
                                      __global const float* restrict d, __global float* restrict out,
                                      const int count, const float bias, const int radius,
                                      const sf_pcf_weights g, __global const float* restrict f,
                                      const sf_plane_params P) {
  const int i = get_global_id(0);
  float ui, vi, di;
  if (!sf_receiver_fetch(i, count, u, v, d, out, &ui, &vi, &di)) return;
  const sf_plane p = sf_receiver_plane_points(i, count, u, v, d, depth, width, height, ui, vi,
                                              clamp(di, 0.0f, 1.0f), P);
  const float b = sf_plane_bias(&p, bias, P);
#if defined(SF_ANISO)
  const sf_aniso a = sf_aniso_at(f, count, i, SF_ANISO);
  float acc = 0.0f;
  for (int k = 0; k < a.n; ++k) {
    const float2 q = sf_aniso_probe(&a, k, width, height, ui, vi);
    acc += sf_pcf_footprint(depth, width, height, q.x, q.y, a.f, a.fx, a.fy, &p, b, radius, &g);
  }
  out[i] = acc / (float)a.n;
#else
  const float fi = f ? f[i] : 1.0f;
  out[i] = sf_pcf_footprint(depth, width, height, ui, vi, fi, fi, fi, &p, b, radius, &g);
#endif
}
#endif

__kernel void sf_pcf_points(__global const float* restrict depth, const int width, const int height,
                            __global const float* restrict u, __global const float* restrict v,
                            __global const float* restrict d, __global float* restrict out,
                            const int count, const float bias, const int radius,
                            const sf_pcf_weights g, const sf_plane_params P) {
  const int i = get_global_id(0);
  float ui, vi, di;
  if (!sf_receiver_fetch(i, count, u, v, d, out, &ui, &vi, &di)) return;
  const sf_plane p = sf_receiver_plane_points(i, count, u, v, d, depth, width, height, ui, vi,
                                              clamp(di, 0.0f, 1.0f), P);
  out[i] = sf_pcf(depth, width, height, &p, sf_plane_bias(&p, bias, P), radius, &g);
}

// --receiver-depth mode: the receiver sits at the texel centre (bilinear weights (1, 0)).
__kernel void sf_pcf_grid(__global const float* restrict depth, const int width, const int height,
                          __global const float* restrict d, __global float* restrict out,
                          const float bias, const int radius, const sf_pcf_weights g,
                          const sf_plane_params P) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  const size_t i = (size_t)y * width + x;
  const float di = d[i];
  if (!isfinite(di)) {
    out[i] = 1.0f;
    return;
  }
  const sf_plane p = sf_receiver_plane_grid(d, depth, width, height, x, y, clamp(di, 0.0f, 1.0f), P);
  out[i] = sf_pcf(depth, width, height, &p, sf_plane_bias(&p, bias, P), radius, &g);
}
