#include "option_names.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace sf::cli {
namespace {

// Field (as the library's messages name it) -> the flag that sets it.
const std::vector<std::pair<std::string, std::string>>& field_flags() {
  static const std::vector<std::pair<std::string, std::string>> table = [] {
    std::vector<std::pair<std::string, std::string>> t = {
        {"FilterOptions::method", "--method"},
        {"FilterOptions::storage", "--storage"},
        {"FilterOptions::esm.c", "--esm-c"},
        {"FilterOptions::blur.radius", "--blur-radius"},
        {"FilterOptions::blur.sigma", "--blur-sigma"},
        {"FilterOptions::depth_test.bias", "--bias"},
        {"FilterOptions::vsm.min_variance", "--vsm-min-variance"},
        {"FilterOptions::vsm.lbr", "--lbr"},
        {"FilterOptions::evsm.pos", "--evsm-pos"},
        {"FilterOptions::evsm.neg", "--evsm-neg"},
        {"FilterOptions::msm.moment_bias", "--msm-bias"},
        {"FilterOptions::csm.order", "--csm-order"},
        {"FilterOptions::csm.alpha", "--csm-alpha"},
        {"FilterOptions::csm.offset", "--csm-offset"},
        {"FilterOptions::csm.scale", "--csm-scale"},
        {"FilterOptions::esm_classify.mode", "--esm-classify"},
        {"FilterOptions::lookup.kind", "--lookup"},
        {"FilterOptions::esm_classify.zmax_offset", "--esm-zmax-offset"},
        {"FilterOptions::esm_classify.threshold_eps", "--esm-threshold-eps"},
        {"FilterOptions::receiver_plane.max_slope", "--receiver-plane-max-slope"},
        {"FilterOptions::receiver_plane.slope_bias", "--slope-bias"},
        {"SoftOptions::receiver_plane.slope_bias", "--slope-bias"},
        {"SoftOptions::receiver_plane.max_slope", "--receiver-plane-max-slope"},
        {"SoftOptions::light.size", "--light-size"},
        {"SoftOptions::light.near_plane", "--light-near"},
        {"SoftOptions::light.fov_degrees", "--light-fov"},
        {"SoftOptions::light.extent", "--light-extent"},
        {"SoftOptions::bias", "--soft-bias"},
        {"SoftOptions::max_width", "--soft-max-width"},
        {"SoftOptions::cssm.order", "--cssm-order"},
        {"SoftOptions::cssm.lookup", "--lookup"},
        {"SoftOptions::cssm.offset", "--cssm-offset"},
        {"SoftOptions::cssm.scale", "--cssm-scale"},
        {"SoftOptions::cssm.sharpen_a", "--cssm-sharpen A"},
        {"SoftOptions::cssm.sharpen_b", "--cssm-sharpen B"},
        {"SoftOptions::cssm.min_den", "--cssm-min-den"},
        {"SoftOptions::cssm.z_offset", "--cssm-z-offset"},
        {"SoftOptions::cssm.width_scale", "--cssm-width-scale"},
        {"SoftOptions::ssmm.n", "--ssmm-n"},
        {"DepthDecoding::near_plane", "--near"},
        {"DepthDecoding::far_plane", "--far"},
        {"DepthDecoding::beyond_far_is_empty", "--beyond-far far"},
        {"CameraDepth::kind", "--camera-depth-kind"},
        {"CameraReceiverOptions::map_width and map_height", "--map-size"},
    };
    // Longest first, so that no field is rewritten through a shorter one it starts with.
    std::stable_sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
    return t;
  }();
  return table;
}

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

}  // namespace

std::string cli_message(std::string s) {
  for (const auto& [field, flag] : field_flags()) {
    for (size_t at = s.find(field); at != std::string::npos; at = s.find(field, at)) {
      const size_t end = at + field.size();
      if (end < s.size() && is_name_char(s[end])) {  // a longer name that starts with this one
        at = end;
        continue;
      }
      s.replace(at, field.size(), flag);
      at += flag.size();
    }
  }
  return s;
}

}  // namespace sf::cli
