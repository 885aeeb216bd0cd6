#pragma once
// Rays and intervals of the scene generator over the core's 3-vector.
#include <cmath>

#include "shadowfilter/vec3.hpp"

namespace sf::scene {

// The core's vector (shadowfilter/vec3.hpp), as the scene generator names it.
using Vec3 = sf::Vec3;
using sf::cross;
using sf::dot;
using sf::length;
using sf::normalize;

// Component access by axis index 0..2 (x, y, z).
inline double component(Vec3 a, int axis) { return a[axis]; }

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit length
  Vec3 at(double t) const { return origin + t * direction; }
};

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};

}  // namespace sf::scene
