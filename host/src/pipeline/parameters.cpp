// Parameters declared once (parameters.hpp): the declarations' builders, their ranges and texts,
// and the walk over every declared parameter.
#include "shadowfilter/parameters.hpp"

#include <cmath>
#include <sstream>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf {

std::string parameter_text(double v) {
  std::ostringstream s;
  s << v;
  std::string t = s.str();
  const size_t e = t.find('e');
  if (e != std::string::npos) {  // "1e-06": drop the exponent's sign "+" and leading zeros
    size_t digits = e + 1;
    if (digits < t.size() && t[digits] == '+') t.erase(digits, 1);
    if (digits < t.size() && t[digits] == '-') ++digits;
    while (digits + 1 < t.size() && t[digits] == '0') t.erase(digits, 1);
  }
  return t;
}

namespace {

std::string num(double v) { return parameter_text(v); }

}  // namespace

bool ParameterRange::contains(double v) const {
  if (std::isnan(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  return hi_open ? v < hi : v <= hi;
}

std::string ParameterRange::text(ParameterType type) const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) {
    if (type == ParameterType::Integer && !lo_open && !hi_open) return "in " + num(lo) + ".." + num(hi);
    return "in " + std::string(lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  }
  if (has_lo) {
    if (lo == 0 && lo_open) return "a positive number";
    return (lo_open ? "greater than " : "at least ") + num(lo);
  }
  if (has_hi) return (hi_open ? "less than " : "at most ") + num(hi);
  return "a number";
}

Parameter Parameter::real(std::string field, std::string flag, std::string metavar, std::string help) {
  Parameter p;
  p.field = std::move(field);
  p.flag = std::move(flag);
  p.metavar = std::move(metavar);
  p.help = std::move(help);
  return p;
}

Parameter Parameter::integer(std::string field, std::string flag, std::string metavar, std::string help) {
  Parameter p = real(std::move(field), std::move(flag), std::move(metavar), std::move(help));
  p.type = ParameterType::Integer;
  return p;
}

Parameter Parameter::choice(std::string field, std::string flag, std::vector<std::string> names, std::string help) {
  std::string metavar;
  for (const auto& n : names) metavar += (metavar.empty() ? "" : "|") + n;
  Parameter p = real(std::move(field), std::move(flag), metavar, std::move(help));
  p.type = ParameterType::Choice;
  p.choices = std::move(names);
  return p;
}

Parameter Parameter::with_default(double value) const {
  const bool named = type == ParameterType::Choice && value >= 0 && value < double(choices.size());
  return with_default(value, named ? choices[size_t(value)] : num(value));
}

Parameter Parameter::with_default(double value, std::string text) const {
  Parameter p = *this;
  p.default_value = value;
  p.default_text = std::move(text);
  return p;
}

Parameter Parameter::resolved_by_method(std::string text) const {
  Parameter p = *this;
  p.default_text = std::move(text);
  return p;
}

Parameter Parameter::within(ParameterRange r) const {
  Parameter p = *this;
  p.range = r;
  return p;
}

Parameter Parameter::unset_when(ParameterUnset u) const {
  Parameter p = *this;
  p.unset = u;
  return p;
}

Parameter Parameter::stored(const std::string& key) const {
  Parameter p = *this;
  p.field = "FilterOptions::parameters." + key;
  const double fallback = default_value;
  p.get = [key, fallback](const FilterOptions& o) {
    const auto it = o.parameters.find(key);
    return it == o.parameters.end() ? fallback : it->second;
  };
  p.set = [key](FilterOptions& o, double v) { o.parameters[key] = v; };
  return p;
}

bool Parameter::is_unset(double v) const {
  switch (unset) {
    case ParameterUnset::Negative:
      return v < 0;
    case ParameterUnset::Zero:
      return v == 0;
    case ParameterUnset::None:
      break;
  }
  return false;
}

std::string Parameter::usage() const {
  std::string s = flag + " " + metavar;
  std::string notes;
  if (!default_text.empty()) notes = "default " + default_text;
  if (range) notes += (notes.empty() ? "" : "; ") + range->text(type);
  return notes.empty() ? s : s + " (" + notes + ")";
}

std::vector<const Parameter*> declared_parameters() {
  std::vector<const Parameter*> out;
  auto add = [&out](const Parameter& p) {
    for (const Parameter* q : out)
      if (q->field == p.field) return;
    out.push_back(&p);
  };
  for (const Parameter& p : filter_parameters()) add(p);
  for (const MethodDesc& m : methods())
    for (const Parameter& p : m.parameters) add(p);
  return out;
}

void check_parameters(const std::vector<Parameter>& params, const FilterOptions& o) {
  for (const Parameter& p : params) {
    if (!p.range) continue;
    const double v = p.get(o);
    if (p.is_unset(v) || p.range->contains(v)) continue;
    throw InputError(p.field + " must be " + p.range->text(p.type) +
                     (p.unset == ParameterUnset::Negative ? " (negative = the default)" : "") + ", got " + num(v));
  }
}

}  // namespace sf
