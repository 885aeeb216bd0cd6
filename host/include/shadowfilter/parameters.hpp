#pragma once
// A parameter declared once, in the spirit of Halide's GeneratorParam: the field as the library's
// messages name it ("FilterOptions::esm.c"), the CLI flag, its default, its range, one line of
// help and how to read and write it on FilterOptions. A method's registration declares its own
// (MethodDesc::parameters); the FilterOptions-wide knobs (storage, depth bias, receiver plane,
// blur, lookup, ESM classification) are one table (filter_parameters()). The CLI's flags, the
// finite checks (require_finite_options), the field-to-flag names of the CLI's messages,
// `shadowfilter methods` and the help texts are generated from these declarations.
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "shadowfilter/options.hpp"

namespace sf {

enum class ParameterType {
  Real,     // a float field
  Integer,  // an int field
  Choice,   // a named value: the value is the index into Parameter::choices
};

// Which values of a parameter mean "the default, resolved by the method" (they pass every range).
enum class ParameterUnset {
  None,
  Negative,  // any value < 0 (vsm.min_variance, csm.offset, ...)
  Zero,      // exactly 0 (blur.sigma: (2R+1)/6); a flag given on the CLI may not ask for it
};

// [lo, hi], either end open; an infinite end is unbounded.
struct ParameterRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  bool contains(double v) const;
  // What the range asks for, for messages and help: "a positive number", "in 1..32", "in [0, 1)".
  std::string text(ParameterType type) const;
};

struct Parameter {
  std::string field;    // as messages name it: "FilterOptions::esm.c"
  std::string flag;     // the CLI's: "--esm-c"
  std::string metavar;  // the value's name in help lines: "C"
  ParameterType type = ParameterType::Real;
  std::vector<std::string> choices;  // Choice: the names, value i is choices[i]
  // Choice: the name's value where the core has its own parser (storage: parse_storage, whose
  // InputError names the known names); empty: the names above, case-insensitive.
  std::function<double(const std::string&)> parse;
  // The default: its value (NaN where the method resolves it) and its text, either the value
  // ("120") or one line saying how it is resolved ("measured per order, docs/methods.md").
  double default_value = std::numeric_limits<double>::quiet_NaN();
  std::string default_text;
  // The values accepted. Checked, for a method's parameters, by the method's validation
  // (sf::check_parameters: "FilterOptions::csm.order must be in 1..32, got 99"); for the
  // FilterOptions-wide knobs, whose stages check their own fields, by the CLI when the flag is
  // parsed. Values that mean "the default" (unset) pass.
  std::optional<ParameterRange> range;
  ParameterUnset unset = ParameterUnset::None;
  std::string help;  // one line
  std::function<double(const FilterOptions&)> get;
  std::function<void(FilterOptions&, double)> set;

  // Declarations read as one expression: Parameter::real("FilterOptions::esm.c", "--esm-c", "C",
  // "ESM exponent c").with_default(120).within({0, inf, true}).on(&FilterOptions::esm, &EsmOptions::c).
  static Parameter real(std::string field, std::string flag, std::string metavar, std::string help);
  static Parameter integer(std::string field, std::string flag, std::string metavar, std::string help);
  static Parameter choice(std::string field, std::string flag, std::vector<std::string> names, std::string help);
  Parameter with_default(double value) const;  // default_text: the value
  Parameter with_default(double value, std::string text) const;
  Parameter resolved_by_method(std::string text) const;  // no value: the method resolves it
  Parameter within(ParameterRange r) const;
  Parameter unset_when(ParameterUnset u) const;
  // Read and written as the member `inner` of FilterOptions' member `outer` (o.esm.c).
  template <class S, class T>
  Parameter on(S FilterOptions::*outer, T S::*inner) const {
    Parameter p = *this;
    p.get = [outer, inner](const FilterOptions& o) { return double(o.*outer.*inner); };
    p.set = [outer, inner](FilterOptions& o, double v) { o.*outer.*inner = static_cast<T>(v); };
    return p;
  }
  // Read and written as FilterOptions' own member `field` (o.normal_offset).
  template <class T>
  Parameter on(T FilterOptions::*field) const {
    Parameter p = *this;
    p.get = [field](const FilterOptions& o) { return double(o.*field); };
    p.set = [field](FilterOptions& o, double v) { o.*field = static_cast<T>(v); };
    return p;
  }
  // Kept in FilterOptions::parameters under `key` (a method registered without a field of its
  // own): the field is "FilterOptions::parameters.KEY", absent reads as the default value.
  Parameter stored(const std::string& key) const;
  // True when `v` means "the default" (ParameterUnset).
  bool is_unset(double v) const;
  // "--esm-c C (default 120; a positive number)": one entry of a parameters line.
  std::string usage() const;
};

// A value as declarations and messages show it: the shortest round text, exponents without
// leading zeros ("120", "0.02", "1e-6").
std::string parameter_text(double v);

// The FilterOptions-wide knobs, in the order the CLI lists them: storage, depth_test.bias,
// receiver_plane.*, normal_offset, blur.*, lookup.kind, esm_classify.*.
const std::vector<Parameter>& filter_parameters();

// Every declared parameter once: the knobs, then each registered method's in registration order
// (a parameter that several methods share, like --lbr, once).
std::vector<const Parameter*> declared_parameters();

// Throws InputError when a declared parameter of `params` is outside its range in `o`
// ("FilterOptions::csm.order must be in 1..32, got 99").
void check_parameters(const std::vector<Parameter>& params, const FilterOptions& o);

// --- what every front end (the CLI's flags, the Python keywords) does with a given value --------
// The messages below name no flag or keyword: the front end prefixes its own name.

// Whether `p` is one of filter_parameters(), the knobs every method shares.
bool is_filter_knob(const Parameter& p);

// Checks a number given for `p` before it is set: a knob outside its range throws InputError
// "must be <range>, got <v>" (values that mean "the default" pass). The knobs are checked here
// because their stages take 0 or a negative value as "the default", which a value given does not
// ask for; a method's parameters pass here and are checked by the method's validation.
void check_given_value(const Parameter& p, double v);

// A choice's value from its name: p.parse where the parameter has one, else its names
// case-insensitively; InputError "must be a, b or c, got 'x'" (names alphabetical).
double parse_choice(const Parameter& p, const std::string& text);

// The fields the library's messages name, each with its flag: FilterOptions::method as
// "--method", then every declared parameter's (declared_parameters()).
std::vector<std::pair<std::string, std::string>> option_flags();

// `message` with every field of `names` (field -> name) replaced by its name, longest field first
// and whole names only ("FilterOptions::esm.c" is not rewritten inside "FilterOptions::esm.cx").
std::string rename_fields(std::string message, std::vector<std::pair<std::string, std::string>> names);

}  // namespace sf
