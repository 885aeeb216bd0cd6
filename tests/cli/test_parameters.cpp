// Parameters declared once (parameters.hpp): the CLI's flags and field-to-flag names are the
// declarations', the declared defaults are the ones in effect, and a flag several methods share is
// one declaration.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

#include "filter_options.hpp"
#include "option_names.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"

namespace sf::test {
namespace {

TEST(Parameters, EveryDeclarationIsAFlagOfFilterAndNamedInMessages) {
  CLI::App app;
  FilterOptions o;
  cli::add_method_options(app, o);
  cli::add_prefilter_options(app, o);
  const auto declared = declared_parameters();
  EXPECT_GE(declared.size(), 21u);  // 11 knobs, 10 parameters of the library's methods
  for (const Parameter* p : declared) {
    EXPECT_NE(app.get_option_no_throw(p->flag), nullptr) << p->flag;
    EXPECT_EQ(cli::cli_message("bad " + p->field + ", got 2"), "bad " + p->flag + ", got 2") << p->field;
  }
}

// A declared default value is what FilterOptions holds by default (the option structs' own).
TEST(Parameters, DeclaredDefaultsAreTheOptionsDefaults) {
  const FilterOptions defaults;
  size_t checked = 0;
  for (const Parameter* p : declared_parameters()) {
    if (std::isnan(p->default_value)) {
      EXPECT_FALSE(p->default_text.empty()) << p->field << ": a default resolved by the method says how";
      continue;
    }
    EXPECT_EQ(p->get(defaults), p->default_value) << p->field;
    ++checked;
  }
  EXPECT_GE(checked, 12u);
}

// The default texts of defaults that methods resolve name the values the methods use, in every
// storage each method accepts (--msm-bias once said 3e-6 where msm used 1e-4).
TEST(Parameters, ResolvedDefaultTextsNameTheResolvedValues) {
  const std::pair<const char*, const char*> resolved[] = {{"FilterOptions::msm.moment_bias", "moment_bias"},
                                                          {"FilterOptions::vsm.min_variance", "min_variance"},
                                                          {"FilterOptions::evsm.pos", "c+"},
                                                          {"FilterOptions::evsm.neg", "c-"}};
  size_t checked = 0;
  for (const MethodDesc& m : methods())
    for (const Parameter& p : m.parameters)
      for (const auto& [field, key] : resolved) {
        if (p.field != field) continue;
        for (const StorageLimit& s : m.storages) {
          FilterOptions o;
          o.method = m;
          o.storage = s.storage;
          for (const MethodParameter& v : m.parameter_values(o))
            if (v.key == key) {
              EXPECT_NE(p.default_text.find(parameter_text(v.value)), std::string::npos)
                  << m.name << " " << storage_name(s.storage) << ": " << p.flag << " says '" << p.default_text
                  << "', the method uses " << parameter_text(v.value);
              ++checked;
            }
        }
      }
  EXPECT_GE(checked, 12u);
}

TEST(Parameters, SharedFlagsAreOneDeclaration) {
  size_t lbr = 0, pos = 0;
  for (const Parameter* p : declared_parameters()) {
    lbr += p->flag == "--lbr";
    pos += p->flag == "--evsm-pos";
  }
  EXPECT_EQ(lbr, 1u);
  EXPECT_EQ(pos, 1u);
  size_t declaring_lbr = 0;
  for (const MethodDesc& m : methods())
    for (const Parameter& p : m.parameters) declaring_lbr += p.flag == "--lbr";
  EXPECT_EQ(declaring_lbr, 3u);  // vsm, evsm2, evsm4
}

TEST(Parameters, RangesAndTheirTexts) {
  EXPECT_EQ(ParameterRange({1, 32}).text(ParameterType::Integer), "in 1..32");
  EXPECT_EQ(ParameterRange({0, 1, false, true}).text(ParameterType::Real), "in [0, 1)");
  EXPECT_EQ(ParameterRange({0, INFINITY, true}).text(ParameterType::Real), "a positive number");
  EXPECT_FALSE(ParameterRange({0, 1, false, true}).contains(1.0));
  EXPECT_FALSE(ParameterRange({0, 1}).contains(NAN));
  EXPECT_TRUE(ParameterRange({0, 1}).contains(1.0));
  EXPECT_EQ(parameter_text(1e-6), "1e-6");
  EXPECT_EQ(parameter_text(0.02f), "0.02");
  FilterOptions o;
  o.csm.order = 40;
  o.method = "csm";
  try {
    validate_options(o);
    FAIL() << "csm.order 40 was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "FilterOptions::csm.order must be in 1..32, got 40");
  }
  o.csm.order = 8;
  o.csm.offset = -1;  // negative: the default
  EXPECT_NO_THROW(validate_options(o));
}

}  // namespace
}  // namespace sf::test
