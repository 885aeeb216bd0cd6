#pragma once
// The one 3-vector of the project, in double precision: points and directions of the view
// projections, the cascade layouts, the coherent maps' views and the scene generator. Components
// by name (p.x) or by axis index (p[0]), as the math reads.
#include <cmath>

namespace sf {

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
  double& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  double operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline bool operator==(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
inline bool operator!=(const Vec3& a, const Vec3& b) { return !(a == b); }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
// a / |a|: the caller knows a is not zero.
inline Vec3 normalize(const Vec3& a) { return (1.0 / length(a)) * a; }
// a / |a|, or zero for the zero vector (normals of degenerate neighbourhoods).
inline Vec3 normalized(const Vec3& a) {
  const double l = length(a);
  return l > 0.0 ? (1.0 / l) * a : Vec3{0.0, 0.0, 0.0};
}

}  // namespace sf
