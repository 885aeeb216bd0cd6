// sm and pcf: the shadow test evaluated per depth texel, then weighted (methods.md sec. 2-3):
//   v = sum_t W_x(t) H(z_t - d + bias)
// with W_x the composite Gaussian (x) bilinear weights of the prefilter lookup (sm: radius 0,
// the bilinear weights alone). Needs common.clh before it. Reads the raw float32 depth map.
//
// Both factors are separable and so are the clamp-to-edge rules, so W_x(t) = wx(i) wy(j) over
// a (2R+2)^2 window: with the bilinear taps x0 <= x1 (clamped, x1 - x0 = dx in {0, 1}) and
// the Gaussian g, the texel x0 + o gets wx = (1 - ax) g(o) + ax g(o - dx) (g = 0 beyond R),
// exactly the weight the blur-then-bilinear path gives it, so brute force costs (2R+2)^2 tests.

#define SF_PCF_MAX_RADIUS 64

typedef struct {
  float w[SF_PCF_MAX_RADIUS + 1];  // normalised Gaussian weights g(0..R)
} sf_pcf_weights;

inline float sf_pcf_g(const sf_pcf_weights* g, int radius, int o) {
  o = abs(o);
  return o <= radius ? g->w[o] : 0.0f;
}

// Texel-space coordinates (x, y) = (u W - 1/2, v H - 1/2), as in sf_lookup_bilinear.
inline float sf_pcf(__global const float* restrict depth, int width, int height, float x, float y,
                    float d, float bias, int radius, const sf_pcf_weights* g) {
  const float xf = floor(x), yf = floor(y);
  const float ax = x - xf, ay = y - yf;
  const int x0 = sf_clampi((int)xf, 0, width - 1), x1 = sf_clampi((int)xf + 1, 0, width - 1);
  const int y0 = sf_clampi((int)yf, 0, height - 1), y1 = sf_clampi((int)yf + 1, 0, height - 1);
  const int dx = x1 - x0, dy = y1 - y0;
  float acc = 0.0f;
  for (int oy = -radius; oy <= radius + 1; ++oy) {
    const float wy = (1.0f - ay) * sf_pcf_g(g, radius, oy) + ay * sf_pcf_g(g, radius, oy - dy);
    if (wy == 0.0f) continue;
    __global const float* row = depth + (size_t)sf_clampi(y0 + oy, 0, height - 1) * width;
    float racc = 0.0f;
    for (int ox = -radius; ox <= radius + 1; ++ox) {
      const float wx = (1.0f - ax) * sf_pcf_g(g, radius, ox) + ax * sf_pcf_g(g, radius, ox - dx);
      const float z = row[sf_clampi(x0 + ox, 0, width - 1)];
      racc += (z - d) + bias >= 0.0f ? wx : 0.0f;
    }
    acc = fma(wy, racc, acc);
  }
  return clamp(acc, 0.0f, 1.0f);
}

__kernel void sf_pcf_points(__global const float* restrict depth, const int width, const int height,
                            __global const float* restrict u, __global const float* restrict v,
                            __global const float* restrict d, __global float* restrict out,
                            const int count, const float bias, const int radius,
                            const sf_pcf_weights g) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    out[i] = 1.0f;
    return;
  }
  const float x = fma(ui, (float)width, -0.5f), y = fma(vi, (float)height, -0.5f);
  out[i] = sf_pcf(depth, width, height, x, y, clamp(di, 0.0f, 1.0f), bias, radius, &g);
}

// --receiver-depth mode: the receiver sits at the texel centre (bilinear weights (1, 0)).
__kernel void sf_pcf_grid(__global const float* restrict depth, const int width, const int height,
                          __global const float* restrict d, __global float* restrict out,
                          const float bias, const int radius, const sf_pcf_weights g) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  const size_t i = (size_t)y * width + x;
  const float di = d[i];
  if (!isfinite(di)) {
    out[i] = 1.0f;
    return;
  }
  out[i] = sf_pcf(depth, width, height, (float)x, (float)y, clamp(di, 0.0f, 1.0f), bias, radius, &g);
}
