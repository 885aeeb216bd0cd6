// The `filter` command's method and knob flags, generated from the declarations
// (parameters.hpp): the FilterOptions-wide knobs and every registered method's parameters, each
// flag once however many methods share it.
#include <algorithm>
#include <cctype>
#include <map>
#include <sstream>

#include "filter_options.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"

namespace sf::cli {
namespace {

// The methods that declare or read the parameter, "sm, pcf" ("" when none names it: a knob of
// every method).
std::string users(const Parameter& p) {
  std::string out;
  for (const MethodDesc& m : methods()) {
    bool uses = std::find(m.reads.begin(), m.reads.end(), p.field) != m.reads.end();
    for (const Parameter& q : m.parameters) uses = uses || q.field == p.field;
    if (uses) out += (out.empty() ? "" : ", ") + m.name;
  }
  return out;
}

bool is_knob(const Parameter& p) {
  for (const Parameter& k : filter_parameters())
    if (k.field == p.field) return true;
  return false;
}

std::string text_of(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The flag's help: who reads it, what it is, its default.
std::string help_of(const Parameter& p, const std::string& methods) {
  std::string h = methods.empty() ? p.help : methods + ": " + p.help;
  if (!p.default_text.empty()) h += " (default " + p.default_text + ")";
  return h;
}

// One flag of a declaration, its value handed to `set`. The knobs' ranges are checked here (their
// stages check their own fields in the library, where 0 or a negative value may mean a default
// that a flag given does not ask for); a method's parameters are checked by the method's
// validation, whose message names the flag (cli_message).
void add_parameter(CLI::App& c, const Parameter& p, const std::function<void(double)>& set, const std::string& help) {
  const bool check = is_knob(p) && p.range.has_value();
  auto checked = [&p, set, check](double v) {
    if (check && !p.range->contains(v) && !(p.unset == ParameterUnset::Negative && v < 0))
      throw CLI::ValidationError(p.flag, "must be " + p.range->text(p.type) + ", got " + text_of(v));
    set(v);
  };
  switch (p.type) {
    case ParameterType::Real:
      c.add_option_function<float>(
          p.flag, [checked](float v) { checked(v); }, help);
      return;
    case ParameterType::Integer:
      c.add_option_function<int>(
          p.flag, [checked](int v) { checked(v); }, help);
      return;
    case ParameterType::Choice:
      break;
  }
  // Names, case-insensitive: "must be a, b or c, got 'x'" for anything else (alphabetical, as
  // every enum option of the command lists its names).
  std::map<std::string, int> names;
  for (size_t i = 0; i < p.choices.size(); ++i) names[p.choices[i]] = int(i);
  std::string listed;
  size_t i = 0;
  for (const auto& entry : names) {
    listed += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + entry.first;
    ++i;
  }
  c.add_option_function<std::string>(
       p.flag,
       [&p, names, listed, set](const std::string& text) {
         if (p.parse) {
           try {
             set(p.parse(text));
             return;
           } catch (const InputError& e) {  // while parsing: a parse error, as every other option's
             throw CLI::ValidationError(p.flag, e.what());
           }
         }
         std::string lower = text;
         for (char& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
         const auto it = names.find(lower);
         if (it == names.end()) throw CLI::ValidationError(p.flag, "must be " + listed + ", got '" + text + "'");
         set(it->second);
       },
       help)
      ->type_name(p.metavar);
}

void add_for_filter(CLI::App& c, FilterOptions& o, const Parameter& p) {
  add_parameter(
      c, p, [&o, &p](double v) { p.set(o, v); }, help_of(p, users(p)));
}

// The knobs of the prefilter and lookup stages (add_prefilter_options); the others belong to the
// method group.
bool is_prefilter_knob(const Parameter& p) {
  for (const char* prefix : {"FilterOptions::blur.", "FilterOptions::lookup.", "FilterOptions::esm_classify."})
    if (p.field.rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace

void add_receiver_plane_options(CLI::App& c, ReceiverPlaneOptions& o, const std::string& methods) {
  for (const Parameter& p : filter_parameters()) {
    if (p.field.rfind("FilterOptions::receiver_plane.", 0) != 0) continue;
    auto set = [&o, &p](double v) {
      FilterOptions f;
      f.receiver_plane = o;
      p.set(f, v);
      o = f.receiver_plane;
    };
    add_parameter(c, p, set, help_of(p, p.field == "FilterOptions::receiver_plane.max_slope" ? "" : methods));
  }
}

void add_method_options(CLI::App& c, FilterOptions& o) {
  c.add_option_function<std::string>(
       "--method",
       [&o](const std::string& name) {
         try {
           o.method = method(name);
         } catch (const InputError& e) {  // while parsing: a parse error, as every other option's
           throw CLI::ValidationError("--method", e.what());
         }
       },
       "Filtering method (see `shadowfilter methods`)")
      ->default_str(o.method.name());
  for (const Parameter& p : filter_parameters())
    if (!is_prefilter_knob(p)) add_for_filter(c, o, p);
  for (const Parameter* p : declared_parameters())
    if (!is_knob(*p)) add_for_filter(c, o, *p);
}

void add_prefilter_options(CLI::App& c, FilterOptions& o) {
  for (const Parameter& p : filter_parameters())
    if (is_prefilter_knob(p)) add_for_filter(c, o, p);
}

std::string method_summary(const FilterOptions& o) {
  std::ostringstream s;
  s << o.method;
  for (const MethodParameter& p : o.method->parameter_values(o)) s << " " << p.key << "=" << p.value;
  if (!o.method->raw_depth) s << " storage=" << storage_name(o.storage);
  return s.str();
}

}  // namespace sf::cli
