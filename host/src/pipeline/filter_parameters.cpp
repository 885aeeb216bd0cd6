// The FilterOptions-wide knobs, each declared once (parameters.hpp). Their defaults are the
// option structs' own (options.hpp), read here rather than written again.
#include <limits>

#include "shadowfilter/blur.hpp"
#include "shadowfilter/footprint.hpp"
#include "shadowfilter/normal_offset.hpp"
#include "shadowfilter/parameters.hpp"

namespace sf {

const std::vector<Parameter>& filter_parameters() {
  static const std::vector<Parameter> table = [] {
    const FilterOptions d;  // the defaults
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<Parameter> t;
    Parameter storage = Parameter::choice("FilterOptions::storage", "--storage", {"f32", "f16", "unorm16", "unorm8"},
                                          "Basis image storage (`shadowfilter methods` lists what each method accepts)")
                            .with_default(double(d.storage));
    storage.get = [](const FilterOptions& o) { return double(o.storage); };
    storage.set = [](FilterOptions& o, double v) { o.storage = static_cast<Storage>(int(v)); };
    storage.parse = [](const std::string& name) { return double(parse_storage(name)); };
    t.push_back(storage);

    Parameter bias = Parameter::real("FilterOptions::depth_test.bias", "--bias", "B",
                                     "Depth bias b of the depth tests: H(z - d_t + b), or d - b in the moments")
                         .resolved_by_method("the method's, measured per storage (`shadowfilter methods`)");
    bias.get = [](const FilterOptions& o) { return double(o.depth_test.bias.value_or(0.0f)); };
    bias.set = [](FilterOptions& o, double v) { o.depth_test.bias = float(v); };
    t.push_back(bias);

    Parameter plane = Parameter::choice("FilterOptions::receiver_plane.enabled", "--receiver-plane", {"off", "on"},
                                        "Test each texel against the receiver's plane (on) or its depth d (off)")
                          .with_default(d.receiver_plane.enabled ? 1 : 0);
    plane.get = [](const FilterOptions& o) { return o.receiver_plane.enabled ? 1.0 : 0.0; };
    plane.set = [](FilterOptions& o, double v) { o.receiver_plane.enabled = v != 0; };
    t.push_back(plane);
    t.push_back(Parameter::real("FilterOptions::receiver_plane.max_slope", "--receiver-plane-max-slope", "S",
                                "Largest receiver-plane slope in depth per shadow-map texel (steeper is clamped)")
                    .with_default(d.receiver_plane.max_slope)
                    .on(&FilterOptions::receiver_plane, &ReceiverPlaneOptions::max_slope));
    t.push_back(Parameter::real("FilterOptions::receiver_plane.slope_bias", "--slope-bias", "K",
                                "Texels of the receiver plane's slope |dd/dx| + |dd/dy| added to the bias")
                    .with_default(d.receiver_plane.slope_bias)
                    .on(&FilterOptions::receiver_plane, &ReceiverPlaneOptions::slope_bias));

    t.push_back(
        Parameter::real("FilterOptions::normal_offset", "--normal-offset", "T",
                        "Texels each lookup moves along the receiver's normal (receivers with nx ny nz; 0: off)")
            .resolved_by_method("the method's, measured (`shadowfilter methods`)")
            .within({0, double(kMaxNormalOffset)})
            .unset_when(ParameterUnset::Negative)
            .on(&FilterOptions::normal_offset));

    t.push_back(Parameter::integer("FilterOptions::blur.radius", "--blur-radius", "R",
                                   "Gaussian prefilter radius R (taps -R..R)")
                    .with_default(d.blur.radius)
                    .within({0, double(kMaxBlurRadius)})
                    .on(&FilterOptions::blur, &BlurOptions::radius));
    // 0 is the default (2R+1)/6: a sigma given must be positive.
    t.push_back(Parameter::real("FilterOptions::blur.sigma", "--blur-sigma", "S", "Gaussian sigma in texels")
                    .with_default(d.blur.sigma, "(2R+1)/6")
                    .within({0, inf, true})
                    .unset_when(ParameterUnset::Zero)
                    .on(&FilterOptions::blur, &BlurOptions::sigma));

    Parameter lookup = Parameter::choice("FilterOptions::lookup.kind", "--lookup", {"bilinear", "mips", "sat"},
                                         "Lookup at the receivers: bilinear | mips (trilinear at LOD log2 f) | sat "
                                         "(box of side f); f = the receivers' footprint channel, 1 when missing")
                           .with_default(double(d.lookup.kind));
    lookup.get = [](const FilterOptions& o) { return double(o.lookup.kind); };
    lookup.set = [](FilterOptions& o, double v) { o.lookup.kind = static_cast<Lookup>(int(v)); };
    t.push_back(lookup);
    t.push_back(Parameter::integer("FilterOptions::lookup.max_anisotropy", "--max-anisotropy", "N",
                                   "Most probes along a footprint's major axis (mips, sat, pcf; receivers with "
                                   "dudx dvdx dudy dvdy); 1 = the isotropic lookup at f")
                    .with_default(d.lookup.max_anisotropy)
                    .within({1, double(kMaxAnisotropy)})
                    .on(&FilterOptions::lookup, &LookupOptions::max_anisotropy));

    // Named in the enum's order (EsmClassify: None 0, ZMax 1, Threshold 2, Auto 3).
    Parameter classify =
        Parameter::choice("FilterOptions::esm_classify.mode", "--esm-classify", {"none", "zmax", "threshold", "auto"},
                          "Failure classification: auto (zmax for a method it can classify, none otherwise) | none | "
                          "zmax | threshold; flagged receivers fall back to a 2x2 PCF of the ESM test")
            .with_default(double(d.esm_classify.mode));
    classify.get = [](const FilterOptions& o) { return double(o.esm_classify.mode); };
    classify.set = [](FilterOptions& o, double v) { o.esm_classify.mode = static_cast<EsmClassify>(int(v)); };
    t.push_back(classify);
    t.push_back(Parameter::real("FilterOptions::esm_classify.zmax_offset", "--esm-zmax-offset", "O",
                                "zmax: flag when a texel in the lookup's support has z > d + offset")
                    .with_default(d.esm_classify.zmax_offset)
                    .within({0, 1})
                    .on(&FilterOptions::esm_classify, &EsmClassifyOptions::zmax_offset));
    t.push_back(Parameter::real("FilterOptions::esm_classify.threshold_eps", "--esm-threshold-eps", "E",
                                "threshold: flag when exp(-c d) bar(B) > 1 + eps")
                    .with_default(d.esm_classify.threshold_eps, "exp(c offset)(1+1e-5) - 1, a subset of zmax")
                    .unset_when(ParameterUnset::Negative)
                    .on(&FilterOptions::esm_classify, &EsmClassifyOptions::threshold_eps));
    return t;
  }();
  return table;
}

}  // namespace sf
