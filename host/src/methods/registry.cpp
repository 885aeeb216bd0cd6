// The registry's list and its registrations, method handles, lookups by name and storage, and
// the storage formats.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "embedded_kernels.hpp"
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

bool storage_unorm(Storage s) { return s == Storage::Unorm16 || s == Storage::Unorm8; }

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

// The builders of the library's methods, one per file of host/src/methods/, listed in registry().
MethodDesc raw_depth_method(const std::string& name, const std::string& summary, bool filtered);
MethodDesc esm_method();
MethodDesc vsm_method();
MethodDesc evsm_method(int channels);
MethodDesc msm_method(bool hausdorff);
MethodDesc csm_method();

}  // namespace registration

namespace {

// The registry's checks on a registration, and its validation with the declared ranges first.
MethodDesc checked(MethodDesc d, const std::deque<MethodDesc>& registered) {
  auto refuse = [&d](const std::string& why) { throw InputError("register_method(" + d.name + "): " + why); };
  if (d.name.empty()) throw InputError("register_method: a method needs a name");
  for (const MethodDesc& m : registered)
    if (m.name == d.name) refuse("a method of this name is registered");
  if (!d.channel_count || !d.validate || !d.pack_params || !d.parameter_values)
    refuse("channel_count, validate, pack_params and parameter_values are required");
  if (!d.raw_depth) {
    if (!d.scalar) refuse("a basis method needs its double-precision twin (scalar)");
    if (d.header.empty()) refuse("a basis method needs its kernel header");
    if (d.header_source.empty() && !detail::has_embedded_kernel(d.header))
      refuse("header '" + d.header + "' is not embedded and no header_source is given");
    if (!d.header_source.empty() && detail::has_embedded_kernel(d.header))
      refuse("header '" + d.header + "' would replace the embedded file of that name");
  }
  if (!d.defines) d.defines = [](const FilterOptions&) { return std::string(); };
  // One declaration per field and per flag, whoever declares it.
  std::vector<const Parameter*> others;
  for (const Parameter& p : filter_parameters()) others.push_back(&p);
  for (const MethodDesc& m : registered)
    for (const Parameter& p : m.parameters) others.push_back(&p);
  for (const Parameter& p : d.parameters) {
    if (p.field.empty() || p.flag.empty() || !p.get || !p.set) refuse("parameter '" + p.field + "' is incomplete");
    for (const Parameter* q : others)
      if ((q->field == p.field) != (q->flag == p.flag))
        refuse("parameter " + p.field + " (" + p.flag + ") clashes with " + q->field + " (" + q->flag + ")");
  }
  d.validate = [params = d.parameters, own = d.validate](const FilterOptions& o) {
    check_parameters(params, o);
    own(o);
  };
  return d;
}

std::deque<MethodDesc>& registry() {
  static std::deque<MethodDesc> all = [] {
    using namespace registration;
    std::deque<MethodDesc> d;
    for (MethodDesc m : {
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
         })
      d.push_back(checked(std::move(m), d));
    return d;
  }();
  return all;
}

const MethodDesc& named(const std::string& name) {
  for (const auto& m : methods())
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : methods()) known += (known.empty() ? "" : ", ") + m.name;
  throw InputError("unknown method '" + name + "' (known: " + known + ")");
}

}  // namespace

const std::deque<MethodDesc>& methods() { return registry(); }

Method register_method(MethodDesc desc) {
  std::deque<MethodDesc>& all = registry();
  all.push_back(checked(std::move(desc), all));
  return Method(all.back());
}

Method method(const std::string& name) { return Method(named(name)); }

Method::Method(const std::string& name) : desc_(&named(name)) {}
Method::Method(const char* name) : desc_(&named(name)) {}

const MethodDesc& Method::desc() const {
  static const MethodDesc& esm = named("esm");
  return desc_ ? *desc_ : esm;
}

const std::string& Method::name() const { return desc().name; }

std::ostream& operator<<(std::ostream& out, const Method& m) { return out << m.name(); }

void validate_options(const FilterOptions& o) {
  require_finite_options(o);
  // The knobs every method shares, within their declared ranges (values meaning "the default"
  // pass), so that a FrameFilter or a Pipeline refuses them before any stage runs.
  check_parameters(filter_parameters(), o);
  o.method->validate(o);
}

std::string sat_refusal(const FilterOptions& o, const SatMap& map) {
  const MethodDesc& m = *o.method;
  if (m.raw_depth || o.lookup.kind != Lookup::Sat || !m.sat_limit) return {};
  return m.sat_limit(o, map);
}

size_t basis_bytes_per_texel(const MethodDesc& m, const FilterOptions& o) {
  return size_t(m.channels(o)) * (m.raw_depth ? 4 : storage_bytes(o.storage));
}

EsmClassify classify_mode(const FilterOptions& o) {
  if (o.esm_classify.mode != EsmClassify::Auto) return o.esm_classify.mode;
  return o.method->classifiable ? EsmClassify::ZMax : EsmClassify::None;
}

float normal_offset(const FilterOptions& o) {
  return o.normal_offset >= 0.0f ? o.normal_offset : o.method->default_normal_offset;
}

float depth_bias(const FilterOptions& o) {
  if (o.depth_test.bias) return *o.depth_test.bias;
  return o.method->default_depth_bias(o);
}

}  // namespace sf
