#include "view_raster.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace sf::scene {

namespace {

constexpr int64_t kSub = 256;  // sub-texel steps of the snapped vertex positions

// A vertex in the map: snapped (texel units x kSub) for coverage, unsnapped (texel units) and its
// depth for the depth plane.
struct Snapped {
  int64_t x, y;
  double fx, fy, depth;
};

// Twice the signed area of (a, b, p): > 0 when p lies left of a -> b (counter-clockwise).
int64_t edge(const Snapped& a, const Snapped& b, int64_t px, int64_t py) {
  return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

// edge() on the unsnapped positions: the barycentric weights of the depth.
double edge_exact(const Snapped& a, const Snapped& b, double px, double py) {
  return (b.fx - a.fx) * (py - a.fy) - (b.fy - a.fy) * (px - a.fx);
}

// The top-left rule: a sample exactly on edge a -> b belongs to the triangle when the edge runs
// this way; the neighbour across it runs b -> a and leaves the sample.
bool owns_edge(const Snapped& a, const Snapped& b) {
  const int64_t dx = b.x - a.x, dy = b.y - a.y;
  return dy > 0 || (dy == 0 && dx < 0);
}

}  // namespace

// 10 bits of each coordinate interleaved: nearby points get nearby codes.
uint32_t morton(uint32_t x, uint32_t y, uint32_t z) {
  auto spread = [](uint32_t v) {
    v = (v | (v << 16)) & 0x030000FFu;
    v = (v | (v << 8)) & 0x0300F00Fu;
    v = (v | (v << 4)) & 0x030C30C3u;
    return (v | (v << 2)) & 0x09249249u;
  };
  return spread(x) | (spread(y) << 1) | (spread(z) << 2);
}

ViewRasterizer::ViewRasterizer(const SceneGeometry& object) {
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  for (const TriMesh& m : object.meshes) {
    const uint32_t base = uint32_t(vertices.size());
    vertices.insert(vertices.end(), m.vertices.begin(), m.vertices.end());
    for (const auto& tri : m.triangles) triangles.push_back({base + tri[0], base + tri[1], base + tri[2]});
  }
  has_spheres_ = !object.spheres.empty();
  if (vertices.empty()) return;
  // Vertices in Morton order of their position and triangles in order of their first vertex: a
  // view reads them in a stream that stays in cache, where a mesh file's order jumps about.
  Vec3 lo = vertices[0], hi = vertices[0];
  for (const Vec3& v : vertices) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  auto cell = [](double v, double a, double b) {
    return uint32_t(std::clamp(b > a ? (v - a) / (b - a) * 1023.0 : 0.0, 0.0, 1023.0));
  };
  std::vector<std::pair<uint32_t, uint32_t>> order(vertices.size());
  for (size_t k = 0; k < vertices.size(); ++k) {
    const Vec3& v = vertices[k];
    order[k] = {morton(cell(v.x, lo.x, hi.x), cell(v.y, lo.y, hi.y), cell(v.z, lo.z, hi.z)), uint32_t(k)};
  }
  std::sort(order.begin(), order.end());
  std::vector<uint32_t> renumber(vertices.size());
  vertices_.resize(vertices.size());
  for (size_t k = 0; k < order.size(); ++k) {
    renumber[order[k].second] = uint32_t(k);
    vertices_[k] = vertices[order[k].second];
  }
  for (auto& tri : triangles)
    for (uint32_t& v : tri) v = renumber[v];
  std::sort(triangles.begin(), triangles.end(), [](const auto& a, const auto& b) {
    return std::min({a[0], a[1], a[2]}) < std::min({b[0], b[1], b[2]});
  });
  triangles_ = std::move(triangles);
}

void ViewRasterizer::render(const OrthoView& v, int hits, double gap, std::vector<double>& t) const {
  const int m = v.resolution;
  t.assign(size_t(m) * size_t(m) * size_t(hits), std::numeric_limits<double>::infinity());
  const double scale = m / (2.0 * v.half);  // texels per world unit
  // Every vertex snapped once a view, 8 bytes each (the triangles read them in mesh order, so
  // the table should stay in cache); the exact projection only for triangles that cover a centre.
  std::vector<int32_t> xy(2 * vertices_.size());
  for (size_t k = 0; k < vertices_.size(); ++k) {
    const Vec3 r = vertices_[k] - v.centre;
    xy[2 * k] = int32_t(std::nearbyint((dot(r, v.right) * scale + 0.5 * m) * kSub));
    xy[2 * k + 1] = int32_t(std::nearbyint((dot(r, v.up) * scale + 0.5 * m) * kSub));
  }
  auto vertex = [&](uint32_t k) {
    const Vec3 r = vertices_[k] - v.centre;
    return Snapped{xy[2 * k], xy[2 * k + 1], dot(r, v.right) * scale + 0.5 * m, dot(r, v.up) * scale + 0.5 * m,
                   v.half_depth - dot(r, v.dir)};
  };
  const int64_t half_step = kSub / 2;  // texel x's centre is x kSub + kSub / 2
  for (const auto& tri : triangles_) {
    const int64_t ax = xy[2 * tri[0]], ay = xy[2 * tri[0] + 1], bx = xy[2 * tri[1]], by = xy[2 * tri[1] + 1];
    const int64_t cx_ = xy[2 * tri[2]], cy_ = xy[2 * tri[2] + 1];
    // Texel centres inside the bounds (x kSub + kSub/2 in [lo, hi]): most triangles have none.
    const int64_t lo_x = std::min({ax, bx, cx_}), hi_x = std::max({ax, bx, cx_});
    const int64_t lo_y = std::min({ay, by, cy_}), hi_y = std::max({ay, by, cy_});
    const int64_t x0 = std::max<int64_t>(0, (lo_x - half_step + kSub - 1) / kSub);
    const int64_t x1 = std::min<int64_t>(m - 1, (hi_x - half_step) >= 0 ? (hi_x - half_step) / kSub : -1);
    if (x0 > x1) continue;
    const int64_t y0 = std::max<int64_t>(0, (lo_y - half_step + kSub - 1) / kSub);
    const int64_t y1 = std::min<int64_t>(m - 1, (hi_y - half_step) >= 0 ? (hi_y - half_step) / kSub : -1);
    if (y0 > y1) continue;
    Snapped sa = vertex(tri[0]), sb = vertex(tri[1]), sc = vertex(tri[2]);
    const Snapped* a = &sa;
    const Snapped* b = &sb;
    const Snapped* c = &sc;
    int64_t area = edge(*a, *b, c->x, c->y);
    if (area == 0) continue;  // seen edge-on (or degenerate): covers no sample
    if (area < 0) {           // both faces count: orient counter-clockwise
      std::swap(b, c);
      area = -area;
    }
    // The depth plane through the unsnapped vertices (snapping moves a steep face by many depth
    // steps).
    const double area_exact = edge_exact(*a, *b, c->fx, c->fy);
    if (!(std::abs(area_exact) > 0.0)) continue;
    const double inv_area = 1.0 / area_exact;
    const bool own_a = owns_edge(*b, *c), own_b = owns_edge(*c, *a), own_c = owns_edge(*a, *b);
    for (int64_t y = y0; y <= y1; ++y) {
      const int64_t py = y * kSub + half_step;
      for (int64_t x = x0; x <= x1; ++x) {
        const int64_t px = x * kSub + half_step;
        const int64_t wa = edge(*b, *c, px, py), wb = edge(*c, *a, px, py), wc = edge(*a, *b, px, py);
        if (wa < 0 || wb < 0 || wc < 0) continue;
        if ((wa == 0 && !own_a) || (wb == 0 && !own_b) || (wc == 0 && !own_c)) continue;
        const double cx = double(x) + 0.5, cy = double(y) + 0.5;
        const double d = (edge_exact(*b, *c, cx, cy) * a->depth + edge_exact(*c, *a, cx, cy) * b->depth +
                          edge_exact(*a, *b, cx, cy) * c->depth) *
                         inv_area;
        // Keep the `hits` nearest, sorted; a crossing within `gap` of a kept one is the same.
        double* h = t.data() + (size_t(y) * size_t(m) + size_t(x)) * size_t(hits);
        bool same = false;
        for (int k = 0; k < hits; ++k) same = same || std::abs(h[k] - d) <= gap;
        if (same || d >= h[hits - 1]) continue;
        int k = hits - 1;
        for (; k > 0 && h[k - 1] > d; --k) h[k] = h[k - 1];
        h[k] = d;
      }
    }
  }
}

}  // namespace sf::scene
