// The registry's list, lookups by name and storage, and the storage formats.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "registration.hpp"

namespace sf {

const char* storage_name(Storage s) {
  switch (s) {
    case Storage::F32:
      return "f32";
    case Storage::F16:
      return "f16";
    case Storage::Unorm16:
      return "unorm16";
    case Storage::Unorm8:
      return "unorm8";
  }
  return "?";
}

Storage parse_storage(const std::string& name) {
  for (Storage s : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8})
    if (name == storage_name(s)) return s;
  throw InputError("unknown storage '" + name + "' (known: f32, f16, unorm16, unorm8)");
}

int storage_bytes(Storage s) {
  switch (s) {
    case Storage::F32:
      return 4;
    case Storage::F16:
    case Storage::Unorm16:
      return 2;
    case Storage::Unorm8:
      return 1;
  }
  return 4;
}

bool MethodDesc::accepts(Storage s) const {
  return std::any_of(storages.begin(), storages.end(), [s](const StorageLimit& l) { return l.storage == s; });
}

std::string MethodDesc::storage_list() const {
  std::string out;
  for (const auto& l : storages) out += (out.empty() ? "" : " ") + std::string(storage_name(l.storage));
  return out;
}

const StorageLimit& MethodDesc::storage_limit(Storage s) const {
  for (const auto& l : storages)
    if (l.storage == s) return l;
  throw InputError(std::string("FilterOptions::storage ") + storage_name(s) + " does not work with " + name +
                   " (it accepts " + storage_list() + ")");
}

FilterOptions MethodDesc::fitted(FilterOptions o) const {
  const StorageLimit& l = storage_limit(o.storage);
  if (l.fit) l.fit(o);
  return o;
}

namespace registration {

void check_storage(const MethodDesc& m, const FilterOptions& o, const std::string& why) {
  if (m.accepts(o.storage)) return;
  throw InputError(std::string("FilterOptions::storage ") + storage_name(o.storage) + " does not work with " + m.name +
                   " (it accepts " + m.storage_list() + ")" + (why.empty() ? "" : ": " + why));
}

namespace {

// Why the table cannot hold channels of these ranges ("" when it can).
std::string sat_reason(const std::vector<LogRange>& channels, const SatMap& map, double relative_error,
                       const std::string& keeps) {
  std::ostringstream s;
  s << std::setprecision(3);
  for (const LogRange& r : channels) {
    if (r.hi > sat_max_log_value(map)) {
      s << "its float32 entries would overflow: " << map.texels() << " texels of values up to exp(" << r.hi
        << ") sum past exp(" << sat_max_log_value(map) + std::log(double(map.texels())) << ")";
      return s.str();
    }
    if (r.hi - r.lo > sat_max_log_ratio(map, relative_error)) {
      s << "its box means keep " << keeps << " for values spanning up to exp(" << sat_max_log_ratio(map, relative_error)
        << ") on a map of this size, and these span exp(" << r.hi - r.lo << ")";
      return s.str();
    }
    if (r.lo < sat_min_log_value(relative_error)) {
      s << "its float32 entries resolve values down to exp(" << sat_min_log_value(relative_error) << ") for " << keeps
        << ", and these go down to exp(" << r.lo << ")";
      return s.str();
    }
  }
  return {};
}

}  // namespace

std::string sat_exponential_refusal(const std::string& method, const char* exponent, double c,
                                    const std::function<std::vector<LogRange>(double c)>& log_ranges, const SatMap& map,
                                    double relative_error, const std::string& keeps) {
  const std::string why = sat_reason(log_ranges(c), map, relative_error, keeps);
  if (why.empty()) return {};
  // The largest exponent within every limit, by bisection, rounded down to 3 digits.
  double ok = 0, bad = c;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (ok + bad);
    (sat_reason(log_ranges(mid), map, relative_error, keeps).empty() ? ok : bad) = mid;
  }
  std::ostringstream s;
  s << std::setprecision(3) << "FilterOptions::lookup.kind sat cannot hold " << method << " with " << exponent << " "
    << c << " on this " << map.width << "x" << map.height << " map (depths " << map.range.min << " to " << map.range.max
    << "): " << why << "; use FilterOptions::lookup.kind mips";
  if (ok > 0) {
    const double step = std::pow(10.0, std::floor(std::log10(ok)) - 2);
    s << " or " << exponent << " <= " << std::floor(ok / step) * step;
  }
  return s.str();
}

std::vector<StorageLimit> plain_storages(std::initializer_list<Storage> list) {
  std::vector<StorageLimit> out;
  for (Storage s : list) out.push_back({s, "", {}});
  return out;
}

}  // namespace registration

const std::vector<MethodDesc>& methods() {
  using namespace registration;
  static const std::vector<MethodDesc> all = {
      raw_depth_method("sm", "plain shadow-map test H(z - d + b) under the bilinear weights", false),
      raw_depth_method("pcf",
                       "percentage-closer filtering: H(z - d + b) brute force under the "
                       "prefilter's weights (Gaussian (x) bilinear), i.e. s_ref",
                       true),
      esm_method(),
      vsm_method(),
      evsm_method(2),
      evsm_method(4),
      msm_method(false),
      msm_method(true),
      csm_method(),
  };
  return all;
}

std::string sat_refusal(const FilterOptions& o, const SatMap& map) {
  const MethodDesc& m = find_method(o.method);
  if (m.raw_depth || o.lookup.kind != Lookup::Sat || !m.sat_limit) return {};
  return m.sat_limit(o, map);
}

size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o) {
  return size_t(m.channels(o)) * (m.raw_depth ? 4 : storage_bytes(o.storage));
}

EsmClassify classify_mode(const FilterOptions& o) {
  if (o.esm_classify.mode != EsmClassify::Auto) return o.esm_classify.mode;
  return find_method(o.method).classifiable ? EsmClassify::ZMax : EsmClassify::None;
}

float depth_bias(const FilterOptions& o) {
  if (o.depth_test.bias) return *o.depth_test.bias;
  return find_method(o.method).default_depth_bias(o);
}

const MethodDesc& find_method(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : methods()) known += (known.empty() ? "" : ", ") + m.name;
  throw InputError("unknown method '" + name + "' (known: " + known + ")");
}

}  // namespace sf
