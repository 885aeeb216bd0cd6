// Parameters declared once (parameters.hpp): the declarations' builders, their ranges and texts,
// and the walk over every declared parameter.
#include "shadowfilter/parameters.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
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

bool is_filter_knob(const Parameter& p) {
  for (const Parameter& k : filter_parameters())
    if (k.field == p.field) return true;
  return false;
}

void check_given_value(const Parameter& p, double v) {
  if (is_filter_knob(p) && p.range && !p.range->contains(v) && !(p.unset == ParameterUnset::Negative && v < 0))
    throw InputError("must be " + p.range->text(p.type) + ", got " + num(v));
}

double parse_choice(const Parameter& p, const std::string& text) {
  if (p.parse) return p.parse(text);
  std::map<std::string, int> names;  // alphabetical, as every enum option lists its names
  for (size_t i = 0; i < p.choices.size(); ++i) names[p.choices[i]] = int(i);
  std::string lower = text;
  for (char& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (const auto it = names.find(lower); it != names.end()) return it->second;
  std::string listed;
  size_t i = 0;
  for (const auto& entry : names) listed += (i++ == 0 ? "" : (i == names.size() ? " or " : ", ")) + entry.first;
  throw InputError("must be " + listed + ", got '" + text + "'");
}

std::vector<std::pair<std::string, std::string>> option_flags() {
  std::vector<std::pair<std::string, std::string>> t = {{"FilterOptions::method", "--method"}};
  for (const Parameter* p : declared_parameters()) t.emplace_back(p->field, p->flag);
  return t;
}

std::string rename_fields(std::string s, std::vector<std::pair<std::string, std::string>> names) {
  std::stable_sort(names.begin(), names.end(),
                   [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
  auto is_name_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& [field, name] : names) {
    for (size_t at = s.find(field); at != std::string::npos; at = s.find(field, at)) {
      const size_t end = at + field.size();
      if (end < s.size() && is_name_char(s[end])) {  // a longer name that starts with this one
        at = end;
        continue;
      }
      s.replace(at, field.size(), name);
      at += name.size();
    }
  }
  return s;
}

}  // namespace sf
