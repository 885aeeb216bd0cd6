// Direct lighting with coherent shadow maps (Ritschel 2007 sec. 5, 5.1 and 5.2;
// docs/coherent_render.md): one work-item per pixel of a G-buffer, S stratified samples of a lat-long
// environment map and S samples uniform over each rectangular area light. Diffuse surfaces draw
// the environment from its luminance distribution (plain light sampling, the seed's choice);
// glossy ones (modified Phong) draw it from the map or from the BRDF lobe, combined by one-sample
// multiple importance sampling. Visibility from the coherent maps (coherent/query.clh,
// concatenated before this file): nearest view and texel, generalized PCF, or Russian roulette.
// Progressive: each launch is one pass blended into the running mean. Host twin, with the same
// random numbers and float arithmetic: host/scene/coherent_render.cpp (render_host).
//
// Contraction into fma is off: the host twin rounds every operation on its own, and equal
// directions on both sides make the coherent maps and the ray-traced renders differ by visibility only.
#pragma OPENCL FP_CONTRACT OFF

// lowbias32 (Wellons): a counter-based RNG, so a pixel's numbers do not depend on work-group size,
// device or thread order.
inline uint sf_hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// Uniform in [0, 1) with 24 bits, a function of (seed, dimension, pixel, sample) only.
inline float sf_rand(uint seed, uint dim, uint pixel, uint sample) {
  uint h = sf_hash(seed + 0x9e3779b9u * dim);
  h = sf_hash(h ^ pixel);
  h = sf_hash(h ^ sample);
  return (float)(h >> 8) * (1.0f / 16777216.0f);
}

#define SF_BELOW_ONE 0x1.fffffep-1f
#define SF_ROTATION 0xffffffffu  // the sample index of a pixel's rotation (no sample has it)

// Sample s of S in the 2D dimension pair k: a Latin hypercube (first coordinate in stratum s, the
// second in stratum (s stride) mod S, stride coprime to S), jittered within the strata and rotated
// per pixel (Cranley-Patterson) so that every point alone is uniform: the estimate is unbiased and
// each coordinate is stratified.
inline float2 sf_stratified(uint seed, uint k, uint pixel, uint s, uint S, float inv_s, uint stride) {
  const float r0 = sf_rand(seed, 4u * k, pixel, SF_ROTATION);
  const float r1 = sf_rand(seed, 4u * k + 1u, pixel, SF_ROTATION);
  const float j0 = sf_rand(seed, 4u * k + 2u, pixel, s);
  const float j1 = sf_rand(seed, 4u * k + 3u, pixel, s);
  const uint t = (uint)(((ulong)s * (ulong)stride) % (ulong)S);
  float u = ((float)s + j0) * inv_s + r0;
  float v = ((float)t + j1) * inv_s + r1;
  u -= floor(u);
  v -= floor(v);
  return (float2)(min(u, SF_BELOW_ONE), min(v, SF_BELOW_ONE));
}

// The index j in [0, n - 1] with cdf[j] <= u < cdf[j + 1]: never a cell of zero probability.
inline int sf_env_search(__global const float* cdf, int n, float u) {
  int lo = 0, hi = n;
  while (hi - lo > 1) {
    const int mid = (lo + hi) >> 1;
    if (cdf[mid] <= u)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

typedef struct {
  int width, height;
  __global const float4* rgb;
  __global const float* marginal;     // height + 1
  __global const float* conditional;  // height (width + 1)
  __global const float* row_cos;      // height + 1
  __global const float* solid_angle;  // height
} sf_env;

// A direction drawn from the map (host: sample_envmap): the texel by its probability, the point
// uniform in solid angle within it; *pdf in solid angle, *texel the texel's index.
inline float3 sf_env_sample(const sf_env E, float2 u, float* pdf, int* texel) {
  const int y = sf_env_search(E.marginal, E.height, u.x);
  const float py = E.marginal[y + 1] - E.marginal[y];
  __global const float* row = E.conditional + (size_t)y * (size_t)(E.width + 1);
  const int x = sf_env_search(row, E.width, u.y);
  const float px = row[x + 1] - row[x];
  const float ry = min((u.x - E.marginal[y]) / py, SF_BELOW_ONE);
  const float rx = min((u.y - row[x]) / px, SF_BELOW_ONE);
  const float c0 = E.row_cos[y], c1 = E.row_cos[y + 1];
  const float ct = c0 + (c1 - c0) * ry;
  const float st = sqrt(max(0.0f, 1.0f - ct * ct));
  const float phi = ((float)x + rx) * (6.28318530717958647f / (float)E.width);
  *pdf = py * px / E.solid_angle[y];
  *texel = y * E.width + x;
  return (float3)(st * cos(phi), ct, st * sin(phi));
}

// The texel whose cell holds direction d (host: envmap_texel_of).
inline int sf_env_texel_of(const sf_env E, float3 d) {
  const float n = length(d);
  const float t = acos(clamp(d.y / n, -1.0f, 1.0f));
  float p = atan2(d.z, d.x);
  if (p < 0.0f) p += 2.0f * SF_COHERENT_PI;
  const int y = clamp((int)(t / SF_COHERENT_PI * (float)E.height), 0, E.height - 1);
  const int x = clamp((int)(p / (2.0f * SF_COHERENT_PI) * (float)E.width), 0, E.width - 1);
  return y * E.width + x;
}

// The radiance of direction d (nearest texel): what background pixels show.
inline float3 sf_env_lookup(const sf_env E, float3 d) { return E.rgb[sf_env_texel_of(E, d)].xyz; }

// The solid-angle pdf with which sf_env_sample draws a direction inside texel t (host: envmap_pdf).
inline float sf_env_pdf(const sf_env E, int t) {
  const int y = t / E.width, x = t - y * E.width;
  __global const float* row = E.conditional + (size_t)y * (size_t)(E.width + 1);
  return (E.marginal[y + 1] - E.marginal[y]) * (row[x + 1] - row[x]) / E.solid_angle[y];
}

// The glossy lobe of the modified Phong BRDF (Lafortune and Willems 1994): pi f = albedo +
// ks (n + 2) / 2 max(0, R.w)^n, R the mirror direction of the view. Energy conserving while
// albedo + ks <= 1 per channel (the command checks it).
inline float sf_phong_cos(float3 R, float3 w) { return max(dot(R, w), 0.0f); }
inline float3 sf_phong_pi_f(float3 albedo, float3 ks, float n, float3 R, float3 w) {
  return albedo + ks * ((n + 2.0f) * 0.5f * pow(sf_phong_cos(R, w), n));
}
// The lobe's own density, (n + 1) / (2 pi) max(0, R.w)^n in solid angle, and a direction drawn
// from it: cos a = u^(1 / (n + 1)), phi = 2 pi v about R (Duff et al. 2017's frame).
inline float sf_phong_pdf(float n, float3 R, float3 w) {
  return (n + 1.0f) * (0.5f / SF_COHERENT_PI) * pow(sf_phong_cos(R, w), n);
}
inline float3 sf_phong_sample(float n, float3 R, float2 u) {
  const float sign = copysign(1.0f, R.z);
  const float a = -1.0f / (sign + R.z);
  const float b = R.x * R.y * a;
  const float3 T = (float3)(1.0f + sign * R.x * R.x * a, sign * b, -sign * R.x);
  const float3 B = (float3)(b, sign + R.y * R.y * a, -R.y);
  const float ca = pow(u.x, 1.0f / (n + 1.0f));
  const float sa = sqrt(max(0.0f, 1.0f - ca * ca));
  const float phi = 2.0f * SF_COHERENT_PI * u.y;
  return T * (sa * cos(phi)) + B * (sa * sin(phi)) + R * ca;
}

// Point corner + ea u.x + eb u.y of a two-sided rectangular light, seen from point p with normal
// N: d = that point - p, w = d / |d|, and the weight of a sample uniform over the rectangle,
// cos(N, w) |cos(n_l, w)| area / |d|^2, or 0 when the receiver faces away or the light is seen
// edge-on (host twin: render_host's lights).
inline float sf_rect_sample(float3 corner, float3 ea, float3 eb, float2 u, float3 p, float3 N, float3* d, float3* w) {
  *d = corner + ea * u.x + eb * u.y - p;
  const float dist2 = dot(*d, *d);
  const float3 nl = cross(ea, eb);
  const float area = length(nl);
  const float dist = sqrt(dist2);
  *w = *d / dist;
  const float c = dot(N, *w);
  const float cl = fabs(dot(nl, *w)) / area;
  return c > 0.0f && cl > 0.0f && dist2 > 0.0f ? c * cl * area / dist2 : 0.0f;
}

// Which visibility lookup the render makes (sf::scene::VisibilityFilter).
#define SF_FILTER_NEAREST 0
#define SF_FILTER_PCF 1
#define SF_FILTER_ROULETTE 2
// Random-number dimensions beside the sample pairs (2D pair k = 0 env, 1 + l light l, dimensions
// 4k .. 4k + 3): the roulette's four numbers of query k are dimensions SF_ROULETTE_DIM + 4k ..
// + 4k + 3, independent per sample (not stratified: a Latin hypercube's first coordinate is
// stratum s in every pair, so stratified roulette numbers would follow the sample's direction
// within the pixel, which measured 1.35x PCF's error at 256 samples on the bunny against 1.07x
// independent); the glossy strategy choice of sample s is dimension SF_CHOICE_DIM (host twin:
// the same constants).
#define SF_ROULETTE_DIM 1024u
#define SF_CHOICE_DIM 4096u

// Visibility of the query of pair k in sample s, through the render's filter, in one object's maps
// (p and d in that object's frame).
inline float sf_render_visibility(const int filter, const sf_coherent_layout L, __global const uint* offsets,
                                  __global const uint* last, __global const ushort* depth,
                                  __global const uint* positions, float3 p, float3 d, uint seed, uint k, uint pixel,
                                  uint s, uint S, float inv_s, uint stride) {
  if (filter == SF_FILTER_PCF) return sf_coherent_visibility_filtered(L, offsets, last, depth, positions, p, d);
  if (filter == SF_FILTER_ROULETTE) {
    const uint dim = SF_ROULETTE_DIM + 4u * k;
    const float4 r = (float4)(sf_rand(seed, dim, pixel, s), sf_rand(seed, dim + 1u, pixel, s),
                              sf_rand(seed, dim + 2u, pixel, s), sf_rand(seed, dim + 3u, pixel, s));
    return sf_coherent_visibility_roulette(L, offsets, last, depth, positions, p, d, r);
  }
  return sf_coherent_visibility(L, offsets, last, depth, positions, p, d);
}

// The objects of the scene (seed sec. 4.6: D' = D T^-1): object o's maps are layouts[o] over the
// concatenated arrays from bases[o] (x: offsets, y: last and depth, z: positions), and
// xforms[3 o .. 3 o + 2] are the rows of its world-to-object transform (xyz the inverse
// rotation's row, w the inverse translation's component). A query's visibility is the product
// over the objects of its visibility in each, the point and direction taken into the object's
// frame (directions by the rotation alone); it stops at the first 0.
typedef struct {
  int count;
  __global const sf_coherent_layout* layouts;
  __global const float4* xforms;
  __global const uint4* bases;
  __global const uint* offsets;
  __global const uint* last;
  __global const ushort* depth;
  __global const uint* positions;
} sf_render_objects;

inline float sf_scene_visibility(const int filter, const sf_render_objects O, float3 p, float3 d, uint seed, uint k,
                                 uint pixel, uint s, uint S, float inv_s, uint stride) {
  float v = 1.0f;
  for (int o = 0; o < O.count && v > 0.0f; ++o) {
    const float4 r0 = O.xforms[3 * o], r1 = O.xforms[3 * o + 1], r2 = O.xforms[3 * o + 2];
    const float3 po = (float3)(r0.x * p.x + r0.y * p.y + r0.z * p.z + r0.w, r1.x * p.x + r1.y * p.y + r1.z * p.z + r1.w,
                               r2.x * p.x + r2.y * p.y + r2.z * p.z + r2.w);
    const float3 dobj = (float3)(r0.x * d.x + r0.y * d.y + r0.z * d.z, r1.x * d.x + r1.y * d.y + r1.z * d.z,
                                 r2.x * d.x + r2.y * d.y + r2.z * d.z);
    const uint4 b = O.bases[o];
    v *= sf_render_visibility(filter, O.layouts[o], O.offsets + b.x, O.last + b.y, O.depth + b.y, O.positions + b.z,
                              po, dobj, seed, k, pixel, s, S, inv_s, stride);
  }
  return v;
}

// A fixed local light's depth cube maps (Ritschel 2007 sec. 3.3 and 4.2; host:
// sf::coherent::cube_project and sf::ref::coherent::local_visibility): params holds the
// rectangle (corner, edge a, edge b), its radiance, far and a mesh light's area (14 floats);
// dims the sampling grid A, B, the resolution M and N = A B (a mesh light: N x 1); the stack
// holds face k of the i-th cube map (in the grid's ordering: positions) at map k N + i.
typedef struct {
  float3 corner, ea, eb, radiance;
  float far;
  int A, B, M, N;
  __global const uint* offsets;
  __global const uint* last;
  __global const ushort* depth;
  __global const uint* positions;
} sf_local_light;

// 1 when point p is lit from sampling point s of grid cell g, else 0: the face of the largest
// |component| of p - s (ties: x, y, z), the texel of its face coordinates, the planar depth.
inline float sf_local_visibility(const sf_local_light Q, int g, float3 s, float3 p) {
  const float3 d = p - s;
  const float ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
  int face;
  float major, u, v;
  // Faces: 0 +x, 1 -x (u = y, v = z); 2 +y, 3 -y (u = z, v = x); 4 +z, 5 -z (u = x, v = y).
  if (ax >= ay && ax >= az) {
    face = d.x >= 0.0f ? 0 : 1;
    major = ax;
    u = d.y;
    v = d.z;
  } else if (ay >= az) {
    face = d.y >= 0.0f ? 2 : 3;
    major = ay;
    u = d.z;
    v = d.x;
  } else {
    face = d.z >= 0.0f ? 4 : 5;
    major = az;
    u = d.x;
    v = d.y;
  }
  const float inv = major > 0.0f ? 1.0f / major : 0.0f;
  const int x = clamp((int)floor((u * inv + 1.0f) * 0.5f * (float)Q.M), 0, Q.M - 1);
  const int y = clamp((int)floor((v * inv + 1.0f) * 0.5f * (float)Q.M), 0, Q.M - 1);
  const uint q = (uint)clamp(rint(major / Q.far * SF_COHERENT_DEPTH_MAX), 0.0f, SF_COHERENT_DEPTH_MAX);
  const uint map = (uint)face * (uint)Q.N + Q.positions[g];
  const uint t = (uint)(y * Q.M + x);
  return q <= sf_coherent_segment_depth(Q.offsets, Q.last, Q.depth, t, map) ? 1.0f : 0.0f;
}

// gpos: xyz the shading point (lifted off the surface along the normal), w 1 on the object, 0 on
// background; gnormal: the unit normal facing the camera, or on background the camera ray's
// direction; galbedo: diffuse albedo. lights: 4 float4 per light (corner, edge a, edge b,
// radiance), two-sided rectangles outside the object's bounding sphere (semi-local, sec. 4.3).
// filter: SF_FILTER_*. eye: the camera's position; specular: ks (xyz) and the Phong exponent n
// (w); ks = 0 is the diffuse BRDF with plain light sampling. pass: progressive rendering (seed
// sec. 5.2): pass 0 writes out, pass m > 0 blends its estimate in with weight 1 / (m + 1), so out
// holds the mean of the passes so far (each pass with its own seed). out: linear RGB, w = 1.
__kernel void sf_coherent_render(const int n, __global const float4* gpos, __global const float4* gnormal,
                            __global const float4* galbedo, const int n_objects,
                            __global const sf_coherent_layout* layouts, __global const float4* xforms,
                            __global const uint4* bases, __global const uint* offsets, __global const uint* last,
                            __global const ushort* depth, __global const uint* positions, const int env_width,
                            const int env_height, const int env_sampled, __global const float4* env_rgb,
                            __global const float* env_marginal, __global const float* env_conditional,
                            __global const float* env_row_cos, __global const float* env_solid_angle,
                            const int n_lights, __global const float4* lights, const int local_kind,
                            __global const float* local_params, const int4 local_dims,
                            __global const float4* local_points,
                            __global const uint* local_offsets, __global const uint* local_last,
                            __global const ushort* local_depth, __global const uint* local_positions,
                            const uint samples, const float inv_s,
                            const uint stride, const uint seed, const int filter, const float4 eye,
                            const float4 specular, const uint pass, __global float4* out) {
  const int i = (int)get_global_id(0);
  if (i >= n) return;  // the last work-group may be partial
  sf_env E;
  E.width = env_width;
  E.height = env_height;
  E.rgb = env_rgb;
  E.marginal = env_marginal;
  E.conditional = env_conditional;
  E.row_cos = env_row_cos;
  E.solid_angle = env_solid_angle;
  sf_render_objects O;
  O.count = n_objects;
  O.layouts = layouts;
  O.xforms = xforms;
  O.bases = bases;
  O.offsets = offsets;
  O.last = last;
  O.depth = depth;
  O.positions = positions;
  sf_local_light Q;
  Q.corner = vload3(0, local_params);
  Q.ea = vload3(1, local_params);
  Q.eb = vload3(2, local_params);
  Q.radiance = vload3(3, local_params);
  Q.far = local_params[12];
  Q.A = local_dims.x;
  Q.B = local_dims.y;
  Q.M = local_dims.z;
  Q.N = local_dims.w;
  Q.offsets = local_offsets;
  Q.last = local_last;
  Q.depth = local_depth;
  Q.positions = local_positions;
  const float4 P = gpos[i];
  const float3 N = gnormal[i].xyz;
  if (P.w == 0.0f) {
    out[i] = (float4)(sf_env_lookup(E, N), 1.0f);
    return;
  }
  const float3 p = P.xyz;
  const float3 albedo = galbedo[i].xyz;
  const float3 ks = specular.xyz;
  const float shine = specular.w;
  const int glossy = ks.x > 0.0f || ks.y > 0.0f || ks.z > 0.0f;
  // Glossy: the view's mirror direction R, and the probability q of drawing the environment
  // sample from the map rather than from the lobe (one-sample MIS, balance heuristic).
  float3 R = N;
  float q = 1.0f;
  if (glossy) {
    const float3 e = eye.xyz - p;
    const float3 wo = e / sqrt(dot(e, e));
    R = N * (2.0f * dot(N, wo)) - wo;
    const float ld = 0.2126f * albedo.x + 0.7152f * albedo.y + 0.0722f * albedo.z;
    const float ls = 0.2126f * ks.x + 0.7152f * ks.y + 0.0722f * ks.z;
    q = clamp(ld / (ld + ls), 0.25f, 0.75f);
  }
  float3 sum = (float3)(0.0f);
  const uint pixel = (uint)i;
  for (uint s = 0; s < samples; ++s) {
    if (env_sampled && !glossy) {
      float pdf;
      int texel;
      const float3 w = sf_env_sample(E, sf_stratified(seed, 0u, pixel, s, samples, inv_s, stride), &pdf, &texel);
      const float c = dot(N, w);
      if (c > 0.0f) {
        const float v = sf_scene_visibility(filter, O, p, w, seed, 0u, pixel, s, samples, inv_s, stride);
        if (v > 0.0f) sum += env_rgb[texel].xyz * (v * c / pdf);
      }
    } else if (env_sampled) {
      const float2 u = sf_stratified(seed, 0u, pixel, s, samples, inv_s, stride);
      float pdf_env;
      int texel;
      float3 w;
      if (sf_rand(seed, SF_CHOICE_DIM, pixel, s) < q) {
        w = sf_env_sample(E, u, &pdf_env, &texel);
      } else {
        w = sf_phong_sample(shine, R, u);
        texel = sf_env_texel_of(E, w);
        pdf_env = sf_env_pdf(E, texel);
      }
      const float c = dot(N, w);
      const float pdf = q * pdf_env + (1.0f - q) * sf_phong_pdf(shine, R, w);
      if (c > 0.0f && pdf > 0.0f) {
        const float v = sf_scene_visibility(filter, O, p, w, seed, 0u, pixel, s, samples, inv_s, stride);
        if (v > 0.0f) sum += env_rgb[texel].xyz * sf_phong_pi_f(albedo, ks, shine, R, w) * (v * c / pdf);
      }
    }
    for (int l = 0; l < n_lights; ++l) {
      const float3 corner = lights[4 * l].xyz, ea = lights[4 * l + 1].xyz, eb = lights[4 * l + 2].xyz;
      const float3 radiance = lights[4 * l + 3].xyz;
      const float2 u = sf_stratified(seed, 1u + (uint)l, pixel, s, samples, inv_s, stride);
      float3 d, w;
      // The light lies outside the bounding sphere, so d is not 0 for points on the object.
      const float g = sf_rect_sample(corner, ea, eb, u, p, N, &d, &w);
      if (g > 0.0f) {
        const float v = sf_scene_visibility(filter, O, p, d, seed, 1u + (uint)l, pixel, s, samples, inv_s, stride);
        if (v > 0.0f) {
          const float3 e = radiance * (v * g);
          sum += glossy ? e * sf_phong_pi_f(albedo, ks, shine, R, w) : e;
        }
      }
    }
    if (local_kind == 2) {
      // A mesh light: sampling point j of the pair's first number (pair 1 + n_lights), standing
      // for area / N of the mesh, seen from its own cube map.
      const float2 u = sf_stratified(seed, 1u + (uint)n_lights, pixel, s, samples, inv_s, stride);
      const int j = min((int)(u.x * (float)Q.N), Q.N - 1);
      const float3 sp = local_points[2 * j].xyz, nl = local_points[2 * j + 1].xyz;
      const float3 d = sp - p;
      const float dist2 = dot(d, d);
      const float dist = sqrt(dist2);
      const float3 w = d / dist;
      const float c = dot(N, w);
      const float cl = fabs(dot(nl, w));
      if (c > 0.0f && cl > 0.0f && dist2 > 0.0f) {
        const float v = sf_local_visibility(Q, j, sp, p);
        if (v > 0.0f) {
          const float3 e = Q.radiance * (v * (c * cl * local_params[13] / dist2));
          sum += glossy ? e * sf_phong_pi_f(albedo, ks, shine, R, w) : e;
        }
      }
    } else if (local_kind == 1) {
      // The local light: a point uniform over the rectangle (pair 1 + n_lights), its visibility
      // from the cube map of the grid cell that holds it.
      const float2 u = sf_stratified(seed, 1u + (uint)n_lights, pixel, s, samples, inv_s, stride);
      float3 d, w;
      const float g = sf_rect_sample(Q.corner, Q.ea, Q.eb, u, p, N, &d, &w);
      if (g > 0.0f) {
        const int a = min((int)(u.x * (float)Q.A), Q.A - 1), b = min((int)(u.y * (float)Q.B), Q.B - 1);
        const float3 sp = Q.corner + Q.ea * (((float)a + 0.5f) / (float)Q.A) + Q.eb * (((float)b + 0.5f) / (float)Q.B);
        const float v = sf_local_visibility(Q, b * Q.A + a, sp, p);
        if (v > 0.0f) {
          const float3 e = Q.radiance * (v * g);
          sum += glossy ? e * sf_phong_pi_f(albedo, ks, shine, R, w) : e;
        }
      }
    }
  }
  // Diffuse: sum holds L V cos / pdf, times albedo / pi here; glossy: sum holds pi f L V cos / pdf.
  const float3 value = glossy ? sum * (0.31830988618379067f * inv_s) : albedo * (0.31830988618379067f * inv_s) * sum;
  if (pass == 0u) {
    out[i] = (float4)(value, 1.0f);
  } else {
    const float3 prev = out[i].xyz;
    out[i] = (float4)(prev + (value - prev) / (float)(pass + 1u), 1.0f);
  }
}
