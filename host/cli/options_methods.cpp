#include <sstream>

#include "filter_options.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {

void add_receiver_plane_options(CLI::App& c, ReceiverPlaneOptions& o, const std::string& methods) {
  c.add_option_function<std::string>(
      "--receiver-plane",
      [&o](const std::string& s) {
        if (s != "on" && s != "off")
          throw CLI::ValidationError("--receiver-plane", "must be on or off, got '" + s + "'");
        o.enabled = s == "on";
      },
      methods + ": test each texel against the receiver's plane (on, default) or its depth d (off)");
  c.add_option("--receiver-plane-max-slope", o.max_slope,
               "Largest receiver-plane slope in depth per shadow-map texel (steeper is clamped)")
      ->capture_default_str();
  c.add_option("--slope-bias", o.slope_bias,
               methods + ": texels of the receiver plane's slope |dd/dx| + |dd/dy| added to the bias")
      ->capture_default_str();
}

void add_method_options(CLI::App& c, FilterOptions& o) {
  c.add_option("--method", o.method, "Filtering method (see `shadowfilter methods`)")->capture_default_str();
  c.add_option_function<std::string>(
      "--storage",
      [&o](const std::string& s) {
        try {
          o.storage = parse_storage(s);
        } catch (const InputError& e) {  // while parsing: a parse error, as every other option's
          throw CLI::ValidationError("--storage", e.what());
        }
      },
      "Basis image storage: f32, f16, unorm16, unorm8 (default f32)");
  c.add_option_function<float>(
      "--bias", [&o](float b) { o.depth_test.bias = b; },
      "Depth bias b for sm, pcf (H(z - d_t + b)) and msm (default: sm, pcf 0.003 with the receiver plane, "
      "0 without; msm 0, msm-hausdorff 3e-4, unorm16: measured)");
  add_receiver_plane_options(c, o.receiver_plane, "sm, pcf");
  c.add_option("--esm-c", o.esm.c, "ESM exponent c")->capture_default_str();
  c.add_option("--vsm-min-variance", o.vsm.min_variance,
               "Minimum variance (vsm: absolute; evsm: relative); default per method and storage");
  c.add_option("--lbr", o.vsm.lbr, "Light-bleeding reduction a in [0,1) (vsm, evsm)")->capture_default_str();
  c.add_option("--evsm-pos", o.evsm.pos,
               "EVSM positive exponent (clamped to the storage's limit; default evsm2 5, evsm4 10)");
  c.add_option("--evsm-neg", o.evsm.neg, "EVSM negative exponent (clamped to the storage's limit; default 5)");
  c.add_option("--msm-bias", o.msm.moment_bias, "MSM moment bias (default 3e-6 f32, 6e-5 unorm16)");
  c.add_option("--csm-order", o.csm.order, "CSM order M (2M basis planes), 1..32")->capture_default_str();
  c.add_option("--csm-alpha", o.csm.alpha, "CSM ringing attenuation alpha")->capture_default_str();
  c.add_option("--csm-offset", o.csm.offset, "CSM depth offset (default: measured per order)");
  c.add_option("--csm-scale", o.csm.scale, "CSM scale (default: measured per order)");
}

std::string method_summary(const FilterOptions& o) {
  std::ostringstream s;
  s << o.method;
  const MethodDesc* m = nullptr;
  for (const auto& d : methods())
    if (d.name == o.method) m = &d;
  if (!m) return s.str();
  for (const MethodParameter& p : m->parameter_values(o)) s << " " << p.key << "=" << p.value;
  if (!m->raw_depth) s << " storage=" << storage_name(o.storage);
  return s.str();
}

}  // namespace sf::cli
