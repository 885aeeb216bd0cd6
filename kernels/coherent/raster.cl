// The views of a coherent stack rasterised on the device (docs/coherent.md, "Views on the
// device"): host/scene/view_raster.cpp's exact coverage and depth, operation for operation, so
// that the maps are the host renderer's bytes. Three passes over a batch of views:
//
//   sf_raster_project  one work-item a (view, vertex): the vertex snapped to 1/256 texel
//                      (coverage) and its unsnapped map position and depth (the depth plane);
//   sf_raster_cover    one a (view, triangle): the texel centres inside its snapped bounds that
//                      the integer edge functions and the top-left rule give it, each appended to
//                      the texel's list (triangle index, depth) by an atomic counter;
//   sf_raster_resolve  one a (view, texel): the list in triangle order (the host's order), the
//                      `hits` nearest crossings kept as the host keeps them (a crossing within
//                      `gap` of a kept one is the same), quantised into z1 and z2 of the map.
//
// Doubles throughout (cl_khr_fp64) and no contraction into fma: the host computes in double
// without fma, and a depth one rounding apart can quantise one step apart. A texel whose list
// outgrows SF_RASTER_LIST crossings flags its view; the host renders such views itself.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

#define SF_RASTER_SUB 256     // sub-texel steps of a snapped vertex (view_raster.cpp's kSub)
#define SF_RASTER_LIST 16     // crossings a texel's list holds
#define SF_NO_SURFACE 65535u  // coherent::kNoSurface
#define SF_DEPTH_MAX 65534.0  // coherent::kDepthMax

// vertices: 3 doubles each (the rasteriser's order); frames: 9 doubles a view of the batch
// (dir, right, up); snapped: 2 ints and exact: 3 doubles (u, v, depth) a (view, vertex).
__kernel void sf_raster_project(const int views, const int nv, __global const double* vertices,
                                __global const double* frames, const double cx, const double cy, const double cz,
                                const double scale, const double half_m, const double half_depth,
                                __global int* snapped, __global double* exact) {
  const size_t gid = get_global_id(0);
  if (gid >= (size_t)views * (size_t)nv) return;  // the last work-group may be partial
  const size_t b = gid / (size_t)nv, k = gid % (size_t)nv;
  __global const double* f = frames + 9 * b;
  const double rx = vertices[3 * k] - cx, ry = vertices[3 * k + 1] - cy, rz = vertices[3 * k + 2] - cz;
  const double u = (rx * f[3] + ry * f[4] + rz * f[5]) * scale + half_m;
  const double v = (rx * f[6] + ry * f[7] + rz * f[8]) * scale + half_m;
  snapped[2 * gid] = (int)rint(u * (double)SF_RASTER_SUB);
  snapped[2 * gid + 1] = (int)rint(v * (double)SF_RASTER_SUB);
  exact[3 * gid] = u;
  exact[3 * gid + 1] = v;
  exact[3 * gid + 2] = half_depth - (rx * f[0] + ry * f[1] + rz * f[2]);
}

typedef struct {
  long x, y;
  double fx, fy, depth;
} sf_raster_vertex;

inline sf_raster_vertex sf_raster_load(__global const int* snapped, __global const double* exact, size_t at) {
  sf_raster_vertex v;
  v.x = snapped[2 * at];
  v.y = snapped[2 * at + 1];
  v.fx = exact[3 * at];
  v.fy = exact[3 * at + 1];
  v.depth = exact[3 * at + 2];
  return v;
}

// Twice the signed area of (a, b, p) on the snapped grid, and on the unsnapped positions.
inline long sf_raster_edge(const sf_raster_vertex a, const sf_raster_vertex b, long px, long py) {
  return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}
inline double sf_raster_edge_exact(const sf_raster_vertex a, const sf_raster_vertex b, double px, double py) {
  return (b.fx - a.fx) * (py - a.fy) - (b.fy - a.fy) * (px - a.fx);
}
// The top-left rule: a sample exactly on edge a -> b belongs to the triangle when the edge runs
// this way.
inline int sf_raster_owns(const sf_raster_vertex a, const sf_raster_vertex b) {
  const long dx = b.x - a.x, dy = b.y - a.y;
  return dy > 0 || (dy == 0 && dx < 0);
}

// triangles: 3 vertex indices each; counts: a uint a (view, texel), zero before the pass; the
// lists: SF_RASTER_LIST (triangle, depth) entries a (view, texel).
__kernel void sf_raster_cover(const int views, const int nt, __global const uint* triangles, const int nv, const int m,
                              __global const int* snapped, __global const double* exact, __global uint* counts,
                              __global uint* list_triangle, __global double* list_depth) {
  const size_t gid = get_global_id(0);
  if (gid >= (size_t)views * (size_t)nt) return;
  const size_t b = gid / (size_t)nt, j = gid % (size_t)nt;
  const size_t base = b * (size_t)nv;
  const uint i0 = triangles[3 * j], i1 = triangles[3 * j + 1], i2 = triangles[3 * j + 2];
  const long ax = snapped[2 * (base + i0)], ay = snapped[2 * (base + i0) + 1];
  const long bx = snapped[2 * (base + i1)], by = snapped[2 * (base + i1) + 1];
  const long qx = snapped[2 * (base + i2)], qy = snapped[2 * (base + i2) + 1];
  // Texel centres inside the bounds (x SUB + SUB/2 in [lo, hi]): most triangles have none.
  const long half_step = SF_RASTER_SUB / 2;
  const long lo_x = min(ax, min(bx, qx)), hi_x = max(ax, max(bx, qx));
  const long lo_y = min(ay, min(by, qy)), hi_y = max(ay, max(by, qy));
  const long x0 = max(0L, (lo_x - half_step + SF_RASTER_SUB - 1) / SF_RASTER_SUB);
  const long x1 = min((long)(m - 1), (hi_x - half_step) >= 0 ? (hi_x - half_step) / SF_RASTER_SUB : -1L);
  if (x0 > x1) return;
  const long y0 = max(0L, (lo_y - half_step + SF_RASTER_SUB - 1) / SF_RASTER_SUB);
  const long y1 = min((long)(m - 1), (hi_y - half_step) >= 0 ? (hi_y - half_step) / SF_RASTER_SUB : -1L);
  if (y0 > y1) return;
  sf_raster_vertex A = sf_raster_load(snapped, exact, base + i0);
  sf_raster_vertex B = sf_raster_load(snapped, exact, base + i1);
  sf_raster_vertex C = sf_raster_load(snapped, exact, base + i2);
  const long area = sf_raster_edge(A, B, C.x, C.y);
  if (area == 0) return;  // seen edge-on (or degenerate): covers no sample
  if (area < 0) {         // both faces count: orient counter-clockwise
    const sf_raster_vertex t = B;
    B = C;
    C = t;
  }
  const double area_exact = sf_raster_edge_exact(A, B, C.fx, C.fy);
  if (!(fabs(area_exact) > 0.0)) return;
  const double inv_area = 1.0 / area_exact;
  const int own_a = sf_raster_owns(B, C), own_b = sf_raster_owns(C, A), own_c = sf_raster_owns(A, B);
  const size_t texels = (size_t)m * (size_t)m;
  for (long y = y0; y <= y1; ++y) {
    const long py = y * SF_RASTER_SUB + half_step;
    for (long x = x0; x <= x1; ++x) {
      const long px = x * SF_RASTER_SUB + half_step;
      const long wa = sf_raster_edge(B, C, px, py), wb = sf_raster_edge(C, A, px, py), wc = sf_raster_edge(A, B, px, py);
      if (wa < 0 || wb < 0 || wc < 0) continue;
      if ((wa == 0 && !own_a) || (wb == 0 && !own_b) || (wc == 0 && !own_c)) continue;
      const double cxx = (double)x + 0.5, cyy = (double)y + 0.5;
      const double d = (sf_raster_edge_exact(B, C, cxx, cyy) * A.depth + sf_raster_edge_exact(C, A, cxx, cyy) * B.depth +
                        sf_raster_edge_exact(A, B, cxx, cyy) * C.depth) *
                       inv_area;
      const size_t t = b * texels + (size_t)(y * m + x);
      const uint slot = atomic_inc(&counts[t]);
      if (slot < SF_RASTER_LIST) {
        list_triangle[t * SF_RASTER_LIST + slot] = (uint)j;
        list_depth[t * SF_RASTER_LIST + slot] = d;
      }
    }
  }
}

// t / diameter quantised as coherent's depths (coherent_stack.cpp's quantise).
inline uint sf_raster_quantise(double t, double diameter) {
  return (uint)clamp(rint(t / diameter * SF_DEPTH_MAX), 0.0, SF_DEPTH_MAX);
}

// Map first + b of the stack (z1, z2: ushort, texels a map) from view b's lists; overflow[b] set
// when a texel's list outgrew SF_RASTER_LIST (the map is then the host's to write).
__kernel void sf_raster_resolve(const int views, const int m, const int hits, const double gap, const double diameter,
                                const double radius, const int far_sphere, __global const uint* counts,
                                __global const uint* list_triangle, __global const double* list_depth, const uint first,
                                __global ushort* z1, __global ushort* z2, __global uint* overflow) {
  const size_t texels = (size_t)m * (size_t)m;
  const size_t gid = get_global_id(0);
  if (gid >= (size_t)views * texels) return;
  const size_t b = gid / texels, at = gid % texels;
  const uint n = counts[gid];
  if (n > SF_RASTER_LIST) {
    overflow[b] = 1u;
    return;
  }
  // The list in triangle order: the order the host meets the crossings in.
  uint tri[SF_RASTER_LIST];
  double dep[SF_RASTER_LIST];
  for (uint k = 0; k < n; ++k) {
    uint i = k;
    const uint tk = list_triangle[gid * SF_RASTER_LIST + k];
    const double dk = list_depth[gid * SF_RASTER_LIST + k];
    for (; i > 0 && tri[i - 1] > tk; --i) {
      tri[i] = tri[i - 1];
      dep[i] = dep[i - 1];
    }
    tri[i] = tk;
    dep[i] = dk;
  }
  // Keep the `hits` nearest, sorted; a crossing within `gap` of a kept one is the same.
  double h[3] = {INFINITY, INFINITY, INFINITY};
  for (uint k = 0; k < n; ++k) {
    const double d = dep[k];
    int same = 0;
    for (int q = 0; q < hits; ++q) same = same || fabs(h[q] - d) <= gap;
    if (same || d >= h[hits - 1]) continue;
    int q = hits - 1;
    for (; q > 0 && h[q - 1] > d; --q) h[q] = h[q - 1];
    h[q] = d;
  }
  const size_t out = ((size_t)first + b) * texels + at;
  if (!isfinite(h[0])) {  // a miss: lit for every query
    z1[out] = (ushort)SF_NO_SURFACE;
    z2[out] = (ushort)SF_NO_SURFACE;
    return;
  }
  const uint near = sf_raster_quantise(h[0], diameter);
  uint second = SF_NO_SURFACE;
  if (isfinite(h[hits - 1])) {
    second = sf_raster_quantise(h[hits - 1], diameter);
  } else if (far_sphere) {
    // The ray leaves the bounding sphere at t = R + sqrt(R^2 - r^2), r its distance from the
    // centre's line (the spherical far plane).
    const int x = (int)(at % (size_t)m), y = (int)(at / (size_t)m);
    const double a = (((double)x + 0.5) / (double)m - 0.5) * diameter;
    const double c = (((double)y + 0.5) / (double)m - 0.5) * diameter;
    second = sf_raster_quantise(radius + sqrt(max(0.0, radius * radius - a * a - c * c)), diameter);
  }
  z1[out] = (ushort)near;
  z2[out] = (ushort)max(second, near + 1u);  // a pair thinner than one depth step still separates
}
