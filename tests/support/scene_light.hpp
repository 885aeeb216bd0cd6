#pragma once
// The light of a generated scene (docs/scenes.md) from its shadow map's header, for the soft
// methods of the tests and the measurements (tests/measure).
#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "shadowfilter/soft.hpp"

namespace sf::test {

inline SoftLight header_light(const std::string& path) {
  SoftLight L;
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  const OIIO::ImageSpec& s = in->spec();
  auto num = [&](const char* n) { return std::atof(s.get_string_attribute(n).c_str()); };
  L.perspective = s.get_string_attribute("light_type") == "perspective";
  L.near_plane = num("near");
  L.far_plane = num("far");
  L.size = num("light_size");
  if (s.find_attribute("light_height")) L.height = num("light_height");
  L.fov_degrees = num("fov_degrees");
  std::string e = s.get_string_attribute("ortho_extents");
  for (char& c : e)
    if (c == '[' || c == ']' || c == ',') c = ' ';
  std::istringstream es(e);
  double a = 0, b = 0;
  es >> a >> b;
  L.extent = b - a;
  return L;
}

}  // namespace sf::test
