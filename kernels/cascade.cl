// Layered shadow maps (methods.md sec. 6; host: layered_pipeline.cpp). Every layer is filtered by
// its own pipeline; these two kernels sit around those pipelines' reconstructions:
//   sf_cascade_project: per receiver, the layer choice (sf::select_cascade's rule, in float) and,
//     per layer, the receiver as that layer's reconstruction reads it (u, v, d, footprint f);
//   sf_cascade_blend: the chosen layers' visibilities mixed by the choice's weight.
// Needs shared_types.clh (sf_cascade_params), which every program has. The set is a __constant
// buffer: passed by value, PoCL copied its 592 bytes to every work-item's stack.

typedef struct {
  float u, v, d, w;
} sf_map_point;

// World point p in layer k's map: u = (M0 . p) / (M3 . p), v = (M1 . p) / (M3 . p), d = M2 . p
// (linear depth, not divided: cascades.hpp, LayerTransform).
inline sf_map_point sf_cascade_apply(__constant sf_cascade_params* C, int k, float3 p) {
  __constant const float* m = C->m + 16 * k;
  sf_map_point q;
  q.w = fma(m[12], p.x, fma(m[13], p.y, fma(m[14], p.z, m[15])));
  q.u = fma(m[0], p.x, fma(m[1], p.y, fma(m[2], p.z, m[3]))) / q.w;
  q.v = fma(m[4], p.x, fma(m[5], p.y, fma(m[6], p.z, m[7]))) / q.w;
  q.d = fma(m[8], p.x, fma(m[9], p.y, fma(m[10], p.z, m[11])));
  return q;
}

// Whether layer k's map holds the point (select_cascade's on_map): in front of its projection
// (w > 0) and inside [0, 1]^2. NaN fails every test.
inline bool sf_cascade_on_map(sf_map_point q) {
  return q.w > 0.0f && q.u >= 0.0f && q.u <= 1.0f && q.v >= 0.0f && q.v <= 1.0f;
}

// The gradients of u W and v H over world space at q in layer k: du = (M0 - u M3) W / w and
// dv = (M1 - v M3) H / w.
inline void sf_cascade_gradients(__constant sf_cascade_params* C, int k, sf_map_point q, float3* du, float3* dv) {
  __constant const float* m = C->m + 16 * k;
  const float3 r3 = (float3)(m[12], m[13], m[14]);
  *du = ((float3)(m[0], m[1], m[2]) - q.u * r3) * ((float)C->width / q.w);
  *dv = ((float3)(m[4], m[5], m[6]) - q.v * r3) * ((float)C->height / q.w);
}

// The pixel offsets dx, dy in layer k's texels: (dudx, dvdx, dudy, dvdy), the Jacobian of
// (u W, v H) over the pixel (sf::layer_jacobian; footprint.hpp), non-finite where q is.
inline float4 sf_cascade_texel_offsets(__constant sf_cascade_params* C, int k, sf_map_point q, float3 dx, float3 dy) {
  float3 du, dv;
  sf_cascade_gradients(C, k, q, &du, &dv);
  return (float4)(dot(du, dx), dot(dv, dx), dot(du, dy), dot(dv, dy));
}

// Footprint in layer texels (sf::layer_footprint): the longer of the two offsets.
inline float sf_cascade_footprint(float4 j) {
  const float fx = sqrt(j.x * j.x + j.y * j.y), fy = sqrt(j.z * j.z + j.w * j.w);
  const float f = fmax(fx, fy);
  return isfinite(f) ? f : 1.0f;
}

// The Jacobian as the layer's reconstruction reads it: the identity (footprint 1, as
// sf_cascade_footprint) where a component is not finite.
inline float4 sf_cascade_jacobian(float4 j) { return all(isfinite(j)) ? j : (float4)(1.0f, 0.0f, 0.0f, 1.0f); }

// The normal offset (normal_offset.hpp) in layer k: p moved C->normal_offset of the layer's texels
// along n, a texel being 1 / sqrt(|grad uW| |grad vH|) wide at p (q = p in the layer). n is the
// camera-facing unit normal, -(dx x dy) / |dx x dy|: a pixel's offsets run along the image's x and
// y (row 0 at the top), so their cross product points away from the camera on either side of a
// surface. p itself where the offset is 0, the offsets span no plane or the move is not finite.
inline float3 sf_cascade_moved(__constant sf_cascade_params* C, int k, sf_map_point q, float3 p, float3 n) {
  if (C->normal_offset == 0.0f) return p;
  float3 du, dv;
  sf_cascade_gradients(C, k, q, &du, &dv);
  const float3 moved = p + (C->normal_offset * rsqrt(length(du) * length(dv))) * n;
  return all(isfinite(moved)) ? moved : p;
}

// The camera-facing unit normal of the pixel's offsets (sf_cascade_moved), 0 where they span no plane.
inline float3 sf_cascade_normal(float3 dx, float3 dy) {
  const float3 c = cross(dx, dy);
  const float l = length(c);
  return l > 0.0f && isfinite(l) ? -c / l : (float3)(0.0f);
}

// Receiver i of the view: x, y, z its world position, depth its view depth,
// d?x / d?y the world offsets across its pixel. Writes
//   layers[i] = (first layer, second layer or -1), -1 -1 where no layer serves it (background,
//     a view depth outside the splits, or off every map that could serve it): lit;
//   weight[i] = the second layer's weight (the first's is 1 - weight);
//   per layer k at k * stride + i: u, v, d, f as that layer's reconstruction reads them. Layers
//     that do not serve i get d = NaN, the mark the reconstruction treats as outside (visibility
//     1, never a neighbour of the receiver plane), u = v = 0 and f = 1: no other non-finite
//     value leaves the kernel;
//   where out_jac is not null, per layer k its Jacobian (sf_cascade_jacobian) as four planes of
//     count floats from 4 k stride (DeviceReceivers::jacobian), the identity where k does not serve i.
// The rule is select_cascade's (cascade_layout.cpp), step by step: the layer whose split range
// holds the view depth, else the next one whose map holds p; in the blend band (the last
// `blend` of that layer's range) the next layer rises linearly to weight 1, if p is on its map.
inline void sf_cascade_project_one(__global const float* restrict x, __global const float* restrict y,
                                   __global const float* restrict z, __global const float* restrict depth,
                                   __global const float* restrict dxx, __global const float* restrict dxy,
                                   __global const float* restrict dxz, __global const float* restrict dyx,
                                   __global const float* restrict dyy, __global const float* restrict dyz,
                                   const int count, __constant sf_cascade_params* restrict C, const int stride,
                                   __global char2* restrict layers, __global float* restrict weight,
                                   __global float* restrict out_u, __global float* restrict out_v,
                                   __global float* restrict out_d, __global float* restrict out_f,
                                   __global float* restrict out_jac, const int i) {
  // SF_CASCADES (= C->count, from the host) fixes every loop's trip count: the rule below is
  // written without data-dependent loops so that PoCL runs work-items side by side in SIMD.
  const float3 p = (float3)(x[i], y[i], z[i]);
  const float vd = depth[i];
  int on = 0;  // bit k: layer k's map holds p (no private arrays: PoCL keeps them per item in memory)
  for (int k = 0; k < SF_CASCADES; ++k) on |= sf_cascade_on_map(sf_cascade_apply(C, k, p)) ? 1 << k : 0;
  // The layer whose split range holds vd (the last one past every split_far), then the first
  // from there on whose map holds p.
  int split = 0;
  for (int k = 0; k + 1 < SF_CASCADES; ++k) split += vd >= C->split_far[k] ? 1 : 0;
  int l0 = -1;
  for (int k = SF_CASCADES - 1; k >= 0; --k) l0 = k >= split && (on >> k & 1) ? k : l0;
  if (!(isfinite(vd) && vd >= C->split_near[0] && vd <= C->split_far[SF_CASCADES - 1])) l0 = -1;
  int l1 = -1;
  float w1 = 0.0f;
  for (int k = 0; k + 1 < SF_CASCADES; ++k) {
    const float band = C->blend * (C->split_far[k] - C->split_near[k]);
    const float t = band > 0.0f ? (vd - (C->split_far[k] - band)) / band : 0.0f;
    const bool blends = k == l0 && t > 0.0f && (on >> (k + 1) & 1);
    l1 = blends ? k + 1 : l1;
    w1 = blends ? fmin(t, 1.0f) : w1;
  }
  layers[i] = (char2)((char)l0, (char)l1);
  weight[i] = w1;
  const float3 dx = (float3)(dxx[i], dxy[i], dxz[i]), dy = (float3)(dyx[i], dyy[i], dyz[i]);
  const float3 n = sf_cascade_normal(dx, dy);
  for (int k = 0; k < SF_CASCADES; ++k) {
    const size_t j = (size_t)k * stride + i;
    const bool served = k == l0 || k == l1;
    const sf_map_point q = sf_cascade_apply(C, k, sf_cascade_moved(C, k, sf_cascade_apply(C, k, p), p, n));
    out_u[j] = served ? q.u : 0.0f;
    out_v[j] = served ? q.v : 0.0f;
    out_d[j] = served ? q.d : NAN;
    const float4 offsets = sf_cascade_texel_offsets(C, k, q, dx, dy);
    out_f[j] = served ? sf_cascade_footprint(offsets) : 1.0f;
    if (out_jac) {
      const float4 jac = served ? sf_cascade_jacobian(offsets) : (float4)(1.0f, 0.0f, 0.0f, 1.0f);
      const size_t b = (size_t)4 * k * stride + i, n = (size_t)count;
      out_jac[b] = jac.x;
      out_jac[b + n] = jac.y;
      out_jac[b + 2 * n] = jac.z;
      out_jac[b + 3 * n] = jac.w;
    }
  }
}

// sf_cascade_project_one for SF_CASCADE_VEC receivers at once, as explicit vectors (PoCL does not
// vectorise the scalar rule across work-items: its bit masks and byte stores keep it one item at a
// time). The same arithmetic lane by lane.
#define SF_CASCADE_VEC 16
typedef float16 sf_cfv;
typedef int16 sf_civ;

typedef struct {
  sf_cfv u, v, d, w;
} sf_map_points;

inline sf_map_points sf_cascade_apply_v(__constant sf_cascade_params* C, int k, sf_cfv x, sf_cfv y, sf_cfv z) {
  __constant const float* m = C->m + 16 * k;
  sf_map_points q;
  q.w = fma(m[12], x, fma(m[13], y, fma(m[14], z, m[15])));
  q.u = fma(m[0], x, fma(m[1], y, fma(m[2], z, m[3]))) / q.w;
  q.v = fma(m[4], x, fma(m[5], y, fma(m[6], z, m[7]))) / q.w;
  q.d = fma(m[8], x, fma(m[9], y, fma(m[10], z, m[11])));
  return q;
}

inline sf_civ sf_cascade_on_map_v(sf_map_points q) {
  return (q.w > 0.0f) & (q.u >= 0.0f) & (q.u <= 1.0f) & (q.v >= 0.0f) & (q.v <= 1.0f);
}

// sf_cascade_gradients of every lane: du = (du0, du1, du2), dv = (dv0, dv1, dv2).
typedef struct {
  sf_cfv du0, du1, du2, dv0, dv1, dv2;
} sf_cascade_grads;

inline sf_cascade_grads sf_cascade_gradients_v(__constant sf_cascade_params* C, int k, sf_map_points q) {
  __constant const float* m = C->m + 16 * k;
  const sf_cfv su = (float)C->width / q.w, sv = (float)C->height / q.w;
  sf_cascade_grads g;
  g.du0 = (m[0] - q.u * m[12]) * su, g.du1 = (m[1] - q.u * m[13]) * su, g.du2 = (m[2] - q.u * m[14]) * su;
  g.dv0 = (m[4] - q.v * m[12]) * sv, g.dv1 = (m[5] - q.v * m[13]) * sv, g.dv2 = (m[6] - q.v * m[14]) * sv;
  return g;
}

// sf_cascade_texel_offsets of every lane: (ax, bx, ay, by) = (dudx, dvdx, dudy, dvdy).
typedef struct {
  sf_cfv ax, bx, ay, by;
} sf_cascade_offsets;

inline sf_cascade_offsets sf_cascade_texel_offsets_v(__constant sf_cascade_params* C, int k, sf_map_points q,
                                                     sf_cfv dx0, sf_cfv dx1, sf_cfv dx2, sf_cfv dy0, sf_cfv dy1,
                                                     sf_cfv dy2) {
  const sf_cascade_grads g = sf_cascade_gradients_v(C, k, q);
  sf_cascade_offsets o;
  o.ax = g.du0 * dx0 + g.du1 * dx1 + g.du2 * dx2, o.bx = g.dv0 * dx0 + g.dv1 * dx1 + g.dv2 * dx2;
  o.ay = g.du0 * dy0 + g.du1 * dy1 + g.du2 * dy2, o.by = g.dv0 * dy0 + g.dv1 * dy1 + g.dv2 * dy2;
  return o;
}

// sf_cascade_footprint of every lane.
inline sf_cfv sf_cascade_footprint_v(sf_cascade_offsets o) {
  const sf_cfv f = fmax(sqrt(o.ax * o.ax + o.bx * o.bx), sqrt(o.ay * o.ay + o.by * o.by));
  return select((sf_cfv)(1.0f), f, isfinite(f));
}

// SF_CASCADE_VEC receivers per work-item (the host launches ceil(count / SF_CASCADE_VEC)); the
// last work-item finishes a partial vector receiver by receiver.
__kernel void sf_cascade_project(__global const float* restrict x, __global const float* restrict y,
                                 __global const float* restrict z, __global const float* restrict depth,
                                 __global const float* restrict dxx, __global const float* restrict dxy,
                                 __global const float* restrict dxz, __global const float* restrict dyx,
                                 __global const float* restrict dyy, __global const float* restrict dyz,
                                 const int count, __constant sf_cascade_params* restrict C, const int stride,
                                 __global char2* restrict layers, __global float* restrict weight,
                                 __global float* restrict out_u, __global float* restrict out_v,
                                 __global float* restrict out_d, __global float* restrict out_f,
                                 __global float* restrict out_jac) {
  const int i0 = get_global_id(0) * SF_CASCADE_VEC;
  if (i0 >= count) return;
  if (count - i0 < SF_CASCADE_VEC) {
    for (int i = i0; i < count; ++i)
      sf_cascade_project_one(x, y, z, depth, dxx, dxy, dxz, dyx, dyy, dyz, count, C, stride, layers, weight, out_u,
                             out_v, out_d, out_f, out_jac, i);
    return;
  }
  const sf_cfv px = vload16(0, x + i0), py = vload16(0, y + i0), pz = vload16(0, z + i0);
  const sf_cfv vd = vload16(0, depth + i0);
  sf_civ on = 0;
  for (int k = 0; k < SF_CASCADES; ++k) on |= sf_cascade_on_map_v(sf_cascade_apply_v(C, k, px, py, pz)) & (1 << k);
  sf_civ split = 0;
  for (int k = 0; k + 1 < SF_CASCADES; ++k) split -= vd >= C->split_far[k];  // true is -1
  sf_civ l0 = -1;
  for (int k = SF_CASCADES - 1; k >= 0; --k) l0 = select(l0, (sf_civ)k, (split <= k) & (((on >> k) & 1) != 0));
  const sf_civ inside = isfinite(vd) & (vd >= C->split_near[0]) & (vd <= C->split_far[SF_CASCADES - 1]);
  l0 = select((sf_civ)(-1), l0, inside);
  sf_civ l1 = -1;
  sf_cfv w1 = 0.0f;
  for (int k = 0; k + 1 < SF_CASCADES; ++k) {
    const float band = C->blend * (C->split_far[k] - C->split_near[k]);
    const sf_cfv t = band > 0.0f ? (vd - (C->split_far[k] - band)) / band : (sf_cfv)(0.0f);
    const sf_civ blends = (l0 == k) & (t > 0.0f) & (((on >> (k + 1)) & 1) != 0);
    l1 = select(l1, (sf_civ)(k + 1), blends);
    w1 = select(w1, fmin(t, 1.0f), blends);
  }
  const char16 c0 = convert_char16(l0), c1 = convert_char16(l1);
  vstore16((char16)(c0.s0, c1.s0, c0.s1, c1.s1, c0.s2, c1.s2, c0.s3, c1.s3, c0.s4, c1.s4, c0.s5, c1.s5, c0.s6, c1.s6,
                    c0.s7, c1.s7),
           0, (__global char*)(layers + i0));
  vstore16((char16)(c0.s8, c1.s8, c0.s9, c1.s9, c0.sa, c1.sa, c0.sb, c1.sb, c0.sc, c1.sc, c0.sd, c1.sd, c0.se, c1.se,
                    c0.sf, c1.sf),
           0, (__global char*)(layers + i0 + 8));
  vstore16(w1, 0, weight + i0);
  const sf_cfv dx0 = vload16(0, dxx + i0), dx1 = vload16(0, dxy + i0), dx2 = vload16(0, dxz + i0);
  const sf_cfv dy0 = vload16(0, dyx + i0), dy1 = vload16(0, dyy + i0), dy2 = vload16(0, dyz + i0);
  // The camera-facing normal (sf_cascade_normal), lane by lane as vectors.
  const sf_cfv x0 = dx1 * dy2 - dx2 * dy1, x1 = dx2 * dy0 - dx0 * dy2, x2 = dx0 * dy1 - dx1 * dy0;
  const sf_cfv len = sqrt(x0 * x0 + x1 * x1 + x2 * x2);
  const sf_civ spans = (len > 0.0f) & isfinite(len);
  const sf_cfv n0 = select((sf_cfv)(0.0f), -x0 / len, spans), n1 = select((sf_cfv)(0.0f), -x1 / len, spans),
               n2 = select((sf_cfv)(0.0f), -x2 / len, spans);
  for (int k = 0; k < SF_CASCADES; ++k) {
    const size_t j = (size_t)k * stride + i0;
    const sf_civ served = (l0 == k) | (l1 == k);
    sf_map_points q = sf_cascade_apply_v(C, k, px, py, pz);
    if (C->normal_offset != 0.0f) {  // sf_cascade_moved, as vectors
      const sf_cascade_grads g = sf_cascade_gradients_v(C, k, q);
      const sf_cfv step = C->normal_offset * rsqrt(sqrt(g.du0 * g.du0 + g.du1 * g.du1 + g.du2 * g.du2) *
                                                   sqrt(g.dv0 * g.dv0 + g.dv1 * g.dv1 + g.dv2 * g.dv2));
      const sf_cfv mx = px + step * n0, my = py + step * n1, mz = pz + step * n2;
      const sf_civ finite = isfinite(mx) & isfinite(my) & isfinite(mz);
      q = sf_cascade_apply_v(C, k, select(px, mx, finite), select(py, my, finite), select(pz, mz, finite));
    }
    vstore16(select((sf_cfv)(0.0f), q.u, served), 0, out_u + j);
    vstore16(select((sf_cfv)(0.0f), q.v, served), 0, out_v + j);
    vstore16(select((sf_cfv)(NAN), q.d, served), 0, out_d + j);
    const sf_cascade_offsets o = sf_cascade_texel_offsets_v(C, k, q, dx0, dx1, dx2, dy0, dy1, dy2);
    vstore16(select((sf_cfv)(1.0f), sf_cascade_footprint_v(o), served), 0, out_f + j);
    if (out_jac) {  // sf_cascade_jacobian, as vectors
      const sf_civ use = served & isfinite(o.ax) & isfinite(o.bx) & isfinite(o.ay) & isfinite(o.by);
      const size_t b = (size_t)4 * k * stride + i0, n = (size_t)count;
      vstore16(select((sf_cfv)(1.0f), o.ax, use), 0, out_jac + b);
      vstore16(select((sf_cfv)(0.0f), o.bx, use), 0, out_jac + b + n);
      vstore16(select((sf_cfv)(0.0f), o.ay, use), 0, out_jac + b + 2 * n);
      vstore16(select((sf_cfv)(1.0f), o.by, use), 0, out_jac + b + 3 * n);
    }
  }
}

// visibility[i] = (1 - w) vis[l0] + w vis[l1] of the layers sf_cascade_project chose (vis of
// layer k at k * stride + i, each already in [0, 1]); 1 where no layer serves i.
__kernel void sf_cascade_blend(__global const char2* restrict layers, __global const float* restrict weight,
                               __global const float* restrict vis, const int stride, const int count,
                               __global float* restrict visibility) {
  const int i = get_global_id(0);
  if (i >= count) return;
  const char2 l = layers[i];
  float v = 1.0f;
  if (l.x >= 0) {
    v = vis[(size_t)l.x * stride + i];
    if (l.y >= 0) v = mix(v, vis[(size_t)l.y * stride + i], weight[i]);
  }
  visibility[i] = clamp(v, 0.0f, 1.0f);
}
