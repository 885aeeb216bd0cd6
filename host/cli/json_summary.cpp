#include "json_summary.hpp"

#include <iostream>

#include "filter_options.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {

nlohmann::json stage_ms_json(const StageTimes& t, double scale) {
  nlohmann::json j = nlohmann::json::object();
  auto stage = [&](const char* name, double seconds, bool always) {
    if (always || seconds > 0) j[name] = seconds * 1e3 * scale;
  };
  stage("transform", t.transform, true);
  stage("blur", t.blur, true);
  stage("mips", t.pyramid, false);
  stage("sat", t.sat, false);
  stage("zmax", t.zmax, false);
  stage("classify", t.classify, false);
  stage("reconstruct", t.reconstruct, true);
  stage("upload", t.upload, true);
  stage("download", t.download, true);
  stage("resident", t.resident, false);
  return j;
}

nlohmann::json filter_options_json(const FilterOptions& o) {
  nlohmann::json j;
  j["method"] = o.method.name();
  nlohmann::json parameters = nlohmann::json::object();
  for (const auto& d : methods())
    if (d.name == o.method) {
      for (const MethodParameter& p : d.parameter_values(o)) parameters[p.key] = p.value;
      if (!d.raw_depth) j["storage"] = storage_name(o.storage);
    }
  j["parameters"] = parameters;
  j["blur_radius"] = o.blur.radius;
  j["lookup"] = o.lookup.kind == Lookup::Mips ? "mips" : o.lookup.kind == Lookup::Sat ? "sat" : "bilinear";
  j["summary"] = method_summary(o) + ", " + prefilter_summary(o);
  return j;
}

void print_json(const nlohmann::json& summary) { std::cout << summary.dump() << "\n"; }

}  // namespace sf::cli
