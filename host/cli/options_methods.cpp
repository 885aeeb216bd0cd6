// The `filter` command's method and knob flags, generated from the declarations
// (parameters.hpp): the FilterOptions-wide knobs and every registered method's parameters, each
// flag once however many methods share it.
#include <algorithm>
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

// The flag's help: who reads it, what it is, its default.
std::string help_of(const Parameter& p, const std::string& methods) {
  std::string h = methods.empty() ? p.help : methods + ": " + p.help;
  if (!p.default_text.empty()) h += " (default " + p.default_text + ")";
  return h;
}

// One flag of a declaration, its value handed to `set`: checked and parsed as every front end
// does (check_given_value, parse_choice: parameters.hpp); a method's parameters are checked by the
// method's validation, whose message names the flag (cli_message).
void add_parameter(CLI::App& c, const Parameter& p, const std::function<void(double)>& set, const std::string& help) {
  auto checked = [&p, set](double v) {
    try {
      check_given_value(p, v);
    } catch (const InputError& e) {  // while parsing: a parse error, as every other option's
      throw CLI::ValidationError(p.flag, e.what());
    }
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
      c.add_option_function<std::string>(
           p.flag,
           [&p, set](const std::string& text) {
             try {
               set(parse_choice(p, text));
             } catch (const InputError& e) {
               throw CLI::ValidationError(p.flag, e.what());
             }
           },
           help)
          ->type_name(p.metavar);
      return;
  }
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
    if (!is_filter_knob(*p)) add_for_filter(c, o, *p);
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
