// shadowfilter._core's soft shadows (soft.hpp): pcss, cssm, ssmm and ssmm-improved on numpy
// arrays. The keywords are the `soft` command's flags ("--cssm-order" is cssm_order), its
// messages the library's with the keyword for the field (soft_option_flags()).
#include <nanobind/stl/function.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <functional>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "shadowfilter/soft.hpp"
#include "shadowfilter/view_projection.hpp"

using namespace nanobind::literals;

namespace sfpy {
namespace {

// One keyword of soft(): its flag, what it takes and where it goes. The receiver plane's come from
// the declared parameters (the knobs `filter` shares), the others are SoftOptions' own.
struct SoftKeyword {
  std::string flag;
  enum Kind { Real, Integer, Switch } kind = Real;
  std::function<void(sf::SoftOptions&, double)> set;
};

const std::vector<SoftKeyword>& soft_keywords() {
  using O = sf::SoftOptions;
  static const std::vector<SoftKeyword> table = {
      {"--soft-bias", SoftKeyword::Real, [](O& o, double v) { o.bias = float(v); }},
      {"--soft-max-width", SoftKeyword::Real, [](O& o, double v) { o.max_width = float(v); }},
      {"--normal-offset", SoftKeyword::Real, [](O& o, double v) { o.normal_offset = float(v); }},
      {"--cssm-order", SoftKeyword::Integer, [](O& o, double v) { o.cssm.order = int(v); }},
      {"--cssm-offset", SoftKeyword::Real, [](O& o, double v) { o.cssm.offset = float(v); }},
      {"--cssm-scale", SoftKeyword::Real, [](O& o, double v) { o.cssm.scale = float(v); }},
      {"--cssm-normalise", SoftKeyword::Switch, [](O& o, double v) { o.cssm.normalise = v != 0; }},
      {"--cssm-min-den", SoftKeyword::Real, [](O& o, double v) { o.cssm.min_den = float(v); }},
      {"--cssm-z-offset", SoftKeyword::Real, [](O& o, double v) { o.cssm.z_offset = float(v); }},
      {"--cssm-width-scale", SoftKeyword::Real, [](O& o, double v) { o.cssm.width_scale = float(v); }},
      {"--cssm-contact", SoftKeyword::Switch, [](O& o, double v) { o.cssm.contact = v != 0; }},
      {"--ssmm-n", SoftKeyword::Integer, [](O& o, double v) { o.ssmm.n = int(v); }},
  };
  return table;
}

std::vector<std::string> known_soft_keywords() {
  std::vector<std::string> k = {"lookup", "cssm_sharpen", "cssm_storage"};
  for (const sf::Parameter& p : sf::filter_parameters())
    if (p.field.rfind("FilterOptions::receiver_plane.", 0) == 0) k.push_back(keyword_of(p.flag));
  for (const SoftKeyword& s : soft_keywords()) k.push_back(keyword_of(s.flag));
  return k;
}

void set_soft_option(sf::SoftOptions& o, const std::string& keyword, nb::handle value) {
  if (keyword == "lookup") {  // cssm's lookup: mips or sat, as the command's --lookup
    const std::string text = nb::isinstance<nb::str>(value) ? nb::cast<std::string>(value) : "";
    if (text == "mips" || text == "sat") {
      o.cssm.lookup = text == "mips" ? sf::Lookup::Mips : sf::Lookup::Sat;
      return;
    }
    throw sf::InputError("lookup must be mips or sat, got " + nb::cast<std::string>(nb::repr(value)));
  }
  if (keyword == "cssm_storage") {  // the basis planes' storage by name, as the command's --cssm-storage
    if (!nb::isinstance<nb::str>(value))
      throw sf::InputError("cssm_storage must be a storage name (f32, f16, unorm16), got " +
                           nb::cast<std::string>(nb::repr(value)));
    try {
      o.cssm.storage = sf::parse_storage(nb::cast<std::string>(value));
    } catch (const sf::InputError& e) {
      throw sf::InputError(std::string("cssm_storage: ") + e.what());
    }
    return;
  }
  if (keyword == "cssm_sharpen") {  // (A, B) of eq. 8.9
    nb::sequence pair = nb::isinstance<nb::sequence>(value) && !nb::isinstance<nb::str>(value)
                            ? nb::borrow<nb::sequence>(value)
                            : nb::sequence();
    if (!pair.is_valid() || nb::len(pair) != 2)
      throw sf::InputError("cssm_sharpen: must be (A, B), got " + nb::cast<std::string>(nb::repr(value)));
    o.cssm.sharpen_a = float(number_of("cssm_sharpen A", pair[0], false));
    o.cssm.sharpen_b = float(number_of("cssm_sharpen B", pair[1], false));
    return;
  }
  for (const sf::Parameter& p : sf::filter_parameters())
    if (p.field.rfind("FilterOptions::receiver_plane.", 0) == 0 && keyword_of(p.flag) == keyword) {
      sf::FilterOptions f;
      f.receiver_plane = o.receiver_plane;
      set_filter_option(f, p, keyword, value);
      o.receiver_plane = f.receiver_plane;
      return;
    }
  for (const SoftKeyword& s : soft_keywords())
    if (keyword_of(s.flag) == keyword) {
      if (s.kind == SoftKeyword::Switch && nb::isinstance<nb::bool_>(value)) return s.set(o, nb::cast<bool>(value));
      return s.set(o, number_of(keyword, value, s.kind != SoftKeyword::Real));
    }
  std::string known;
  for (const std::string& k : known_soft_keywords()) known += (known.empty() ? "" : ", ") + k;
  throw sf::InputError("unknown option '" + keyword +
                       "' (known: method, light, light_size, light_type, light_near, "
                       "light_far, light_fov, light_extent, " +
                       known + ")");
}

Output2D run_soft(const Device& device, const std::string& method, const nb::dict& options, const sf::SoftLight& light,
                  const Image2D& depth, const sf::Receivers& receivers) {
  sf::SoftOptions o;
  o.method = sf::find_soft_method(method);
  for (auto [key, value] : options) set_soft_option(o, nb::cast<std::string>(key), value);
  o.light = light;
  sf::SoftResult r = keyword_errors([&] {
    sf::validate(o);
    nb::gil_scoped_release released;
    return sf::soft_filter(device.runtime, o, host_image(depth), receivers);
  });
  return to_numpy(std::move(r.visibility.data), r.visibility.width, r.visibility.height);
}

}  // namespace

void bind_soft(nb::module_& m) {
  nb::class_<sf::SoftLight>(m, "SoftLight",
                            "A rectangular area light: its sides size (along the map's u axis) and height (along v; "
                            "< 0: size, a square), world units, its projection (orthographic with the map's "
                            "width `extent`, or perspective with the full field of view `fov_degrees`) and the view "
                            "depths of d = 0 and d = 1 (near_plane, far_plane)")
      .def(
          "__init__",
          [](sf::SoftLight* self, bool perspective, double size, double near_plane, double far_plane, double extent,
             double fov_degrees, double height) {
            new (self) sf::SoftLight{perspective, size, near_plane, far_plane, extent, fov_degrees, 1.0, height};
          },
          "perspective"_a, "size"_a, "near_plane"_a, "far_plane"_a, "extent"_a, "fov_degrees"_a, "height"_a = -1.0)
      .def_ro("perspective", &sf::SoftLight::perspective)
      .def_ro("size", &sf::SoftLight::size)
      .def_prop_ro("height", [](const sf::SoftLight& l) { return sf::light_height(l); })
      .def_ro("near_plane", &sf::SoftLight::near_plane)
      .def_ro("far_plane", &sf::SoftLight::far_plane)
      .def_ro("extent", &sf::SoftLight::extent)
      .def_ro("fov_degrees", &sf::SoftLight::fov_degrees)
      .def("__repr__", [](const sf::SoftLight& l) {
        return "SoftLight(" +
               std::string(l.perspective ? "perspective, fov " + sf::parameter_text(l.fov_degrees)
                                         : "ortho, extent " + sf::parameter_text(l.extent)) +
               ", size " + sf::parameter_text(l.size) +
               (l.height >= 0.0 ? "x" + sf::parameter_text(l.height) : std::string()) + ", planes " +
               sf::parameter_text(l.near_plane) + ".." + sf::parameter_text(l.far_plane) + ")";
      });
  m.def(
      "soft_light",
      [](const sf::ViewProjection& view, double size, double height) {
        return keyword_errors([&] { return sf::soft_light(view, size, height); });
      },
      "view"_a, "size"_a, "height"_a = -1.0);
  m.def("soft_methods", [] {
    std::vector<std::string> names;
    for (sf::SoftMethod s :
         {sf::SoftMethod::Pcss, sf::SoftMethod::Cssm, sf::SoftMethod::Ssmm, sf::SoftMethod::SsmmImproved})
      names.push_back(sf::soft_method_name(s));
    return names;
  });
  m.def(
      "soft_points",
      [](const Device& device, const std::string& method, const nb::dict& options, const sf::SoftLight& light,
         const Image2D& depth,
         const Image3D& receivers) { return run_soft(device, method, options, light, depth, receivers_of(receivers)); },
      "device"_a, "method"_a, "options"_a, "light"_a, "depth"_a, "receivers"_a);
  m.def(
      "soft_grid",
      [](const Device& device, const std::string& method, const nb::dict& options, const sf::SoftLight& light,
         const Image2D& depth, const Image2D& receiver_depth) {
        return run_soft(device, method, options, light, depth, receiver_grid(receiver_depth));
      },
      "device"_a, "method"_a, "options"_a, "light"_a, "depth"_a, "receiver_depth"_a);
}

}  // namespace sfpy
