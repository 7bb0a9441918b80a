/** @file EkfParamRegistryTest.cpp
 *  @brief The EkfParams registry: every struct field is registered, getters and setters reach the field, ranges agree
 *         with EkfParams::validate, bad values give errors naming the parameter and the source.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "uwb/filter/EkfParamRegistry.h"

namespace uwb {
namespace {

/// Field names declared in `struct <name> { … }` of a header under include/uwb/filter (lines "type name = default;"),
/// each with `prefix` in front: the registry's names of a nested Params struct carry one.
std::set<std::string> fieldsDeclaredInHeader(const std::string& header, const std::string& name,
                                             const std::string& prefix = "") {
  std::ifstream in(std::string(UWB_SOURCE_DIR) + "/include/uwb/filter/" + header);
  EXPECT_TRUE(in) << "cannot read " << header;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::size_t begin = text.find("struct " + name + " {");
  const std::size_t end = text.find("void validate() const;", begin);
  EXPECT_NE(begin, std::string::npos);
  const std::string body = text.substr(begin, end - begin);
  std::set<std::string> names;
  const std::regex field(R"(^\s*[A-Za-z_][\w:<>, ]*\s+([a-z_][a-z0-9_]*)\s*=[^;]*;.*$)");
  std::stringstream lines(body);
  std::string line;
  std::smatch m;
  while (std::getline(lines, line))
    if (std::regex_match(line, m, field)) names.insert(prefix + m[1].str());
  return names;
}

/// The EkfParams fields, with those of its nested FlightModeParams flight_mode as mode_<field>.
std::set<std::string> fieldsDeclaredInHeader() {
  std::set<std::string> names = fieldsDeclaredInHeader("EkfParams.h", "EkfParams");
  const std::set<std::string> mode = fieldsDeclaredInHeader("FlightMode.h", "FlightModeParams", "mode_");
  EXPECT_GT(mode.size(), 10u);
  names.insert(mode.begin(), mode.end());
  return names;
}

TEST(EkfParamRegistry, EveryFieldOfTheStructIsRegisteredOnce) {
  // GIVEN the fields of the EkfParams header and the registry
  const std::set<std::string> declared = fieldsDeclaredInHeader();
  std::set<std::string> registered;
  for (const EkfParamInfo& i : ekfParamRegistry()) {
    // THEN no name is registered twice, and an alias differs from the flag
    EXPECT_TRUE(registered.insert(i.name).second) << i.name << " registered twice";
    EXPECT_NE("--" + i.cli_alias, i.flag());
  }
  // AND both sets are equal (a new field needs its registry line)
  ASSERT_GT(declared.size(), 40u);
  for (const std::string& n : declared) EXPECT_TRUE(registered.count(n)) << n << " is not in the registry";
  for (const std::string& n : registered) EXPECT_TRUE(declared.count(n)) << n << " is not a field of EkfParams";
  // AND the two fields the CLI and Python used to miss are settable
  EkfParams p;
  setEkfParamFromText(p, ekfParamInfo("pair_bias_tau_s"), "2.5", "--pair-bias-tau-s");
  setEkfParamFromText(p, ekfParamInfo("update_predict_dt_s"), "0.002", "--update-predict-dt-s");
  EXPECT_EQ(p.pair_bias_tau_s, 2.5);
  EXPECT_EQ(p.update_predict_dt_s, 0.002);
}

/// A valid value different from the default of `info`.
EkfParamValue otherValidValue(const EkfParamInfo& info, const EkfParams& defaults) {
  const EkfParamValue d = info.get(defaults);
  switch (info.kind) {
    case EkfParamKind::kReal:
    case EkfParamKind::kInteger: {
      const double x = std::get<double>(d);
      const double candidate = info.kind == EkfParamKind::kInteger ? x + 1.0 : x * 1.5 + 0.25;
      if (info.range.contains(candidate)) return candidate;
      return info.range.contains(x - 1.0) ? x - 1.0 : 0.5 * x;  // 0.5 x: a fraction in (0, 1]
    }
    case EkfParamKind::kBool: return !std::get<bool>(d);
    case EkfParamKind::kVec3: return Vec3(std::get<Vec3>(d) + Vec3(0.1, -0.2, 0.3));
    case EkfParamKind::kChoice:
      for (const std::string& c : info.choices)
        if (c != std::get<std::string>(d)) return c;
  }
  return d;
}

TEST(EkfParamRegistry, SettersAndGettersReachTheirOwnFieldOnly) {
  const EkfParams defaults;
  for (const EkfParamInfo& info : ekfParamRegistry()) {
    SCOPED_TRACE(info.name);
    // GIVEN a valid non-default value
    const EkfParamValue v = otherValidValue(info, defaults);
    ASSERT_NE(ekfParamText(defaults, info), [&] {
      EkfParams q;
      info.set(q, v);
      return ekfParamText(q, info);
    }()) << "no distinct value";
    // WHEN it is set through the registry, from its text form as the CLI does
    EkfParams p;
    EkfParams tmp;
    info.set(tmp, v);
    setEkfParamFromText(p, info, ekfParamText(tmp, info), info.flag());
    // THEN the getter returns it, and every other field keeps its default (start_w_p_b also sets its flag)
    EXPECT_EQ(ekfParamText(p, info), ekfParamText(tmp, info));
    for (const EkfParamInfo& other : ekfParamRegistry()) {
      if (other.name == info.name || (info.name == "start_w_p_b" && other.name == "has_start_position")) continue;
      EXPECT_EQ(ekfParamText(p, other), ekfParamText(defaults, other)) << "changed " << other.name;
    }
  }
}

TEST(EkfParamRegistry, RangesAgreeWithValidate) {
  // GIVEN the defaults, THEN both checks accept them
  EXPECT_NO_THROW(EkfParams{}.validate());
  EXPECT_NO_THROW(validateEkfParamRanges(EkfParams{}));
  for (const EkfParamInfo& info : ekfParamRegistry()) {
    if (info.kind != EkfParamKind::kReal && info.kind != EkfParamKind::kInteger) continue;
    SCOPED_TRACE(info.name + " " + info.range.toString());
    // WHEN a value just outside the registry's range (or NaN) is written into the struct
    std::vector<double> outside;
    if (info.kind == EkfParamKind::kReal) outside.push_back(std::nan(""));
    if (std::isfinite(info.range.lo)) outside.push_back(info.range.lo_open ? info.range.lo : info.range.lo - 1e-9);
    if (std::isfinite(info.range.hi)) outside.push_back(info.range.hi_open ? info.range.hi : info.range.hi + 1e-9);
    for (double x : outside) {
      if (info.kind == EkfParamKind::kInteger) x = x < info.range.lo ? info.range.lo - 1 : info.range.hi + 1;
      EkfParams p;
      info.set(p, x);
      // THEN EkfParams::validate and the registry both reject it
      EXPECT_THROW(p.validate(), std::invalid_argument) << x;
      EXPECT_THROW(validateEkfParamRanges(p), std::invalid_argument) << x;
    }
  }
}

TEST(EkfParamRegistry, BadValuesNameTheParameterTheSourceAndTheValue) {
  EkfParams p;
  const auto message = [&](const std::string& name, const std::string& text) {
    try {
      setEkfParamFromText(p, ekfParamInfo(name), text, "--flag");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("tdoa_sigma_m", "-0.1"), "--flag: tdoa_sigma_m must be > 0 (got -0.1)");
  EXPECT_EQ(message("tdoa_sigma_m", "abc"), "--flag: tdoa_sigma_m must be a number (got 'abc')");
  EXPECT_EQ(message("robust_iterations", "2.5"), "--flag: robust_iterations must be a whole number (got 2.5)");
  EXPECT_EQ(message("robust_iterations", "21"), "--flag: robust_iterations must be in [1, 20] (got 21)");
  EXPECT_EQ(message("robust_loss", "tukey"), "--flag: robust_loss must be one of none, huber, cauchy (got tukey)");
  EXPECT_EQ(message("b_t_tag", "1,2"), "--flag: b_t_tag must be three numbers x,y,z (got '1,2')");
  EXPECT_EQ(message("fuse_tof", "yes"), "--flag: fuse_tof must be true or false (got 'yes')");
  EXPECT_THROW(ekfParamInfo("tdoa_sigma"), std::invalid_argument);
  try {  // without a source the message starts with the name
    setEkfParam(p, ekfParamInfo("gate_sigma"), 0.0, "");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "gate_sigma must be > 0 (got 0)");
  }
  EXPECT_EQ(p.tdoa_sigma_m, EkfParams{}.tdoa_sigma_m);  // nothing was set by the failed calls
}

TEST(EkfParamRegistry, FlightModeFieldsAreTheNestedStructs) {
  // GIVEN a flight-mode parameter set through the registry, as the CLI and Python set it
  EkfParams p;
  setEkfParamFromText(p, ekfParamInfo("mode_tdoa_window_s"), "0.8", "--mode-tdoa-window-s");
  // THEN the field of the nested FlightModeParams holds it
  EXPECT_EQ(p.flight_mode.tdoa_window_s, 0.8);
  EXPECT_EQ(ekfParamText(p, ekfParamInfo("mode_tdoa_window_s")), "0.8");
  // AND an ordering that no range can say (the flight heights) is checked by EkfParams::validate
  p = EkfParams{};
  setEkfParam(p, ekfParamInfo("mode_air_max_height_m"), 0.2, "params");  // in its range, below the minimum height
  EXPECT_NO_THROW(validateEkfParamRanges(p));
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(EkfParamRegistry, HelpAndMarkdownShowUnitDefaultAndRange) {
  EXPECT_EQ(ekfParamHelpSuffix(ekfParamInfo("tdoa_sigma_m")), "[m] (default 0.2, > 0)");
  EXPECT_EQ(ekfParamHelpSuffix(ekfParamInfo("robust_loss")), "(default huber; one of none, huber, cauchy)");
  EXPECT_EQ(ekfParamInfo("tdoa_sigma_m").flag(), "--tdoa-sigma-m");
  const std::string table = ekfParamMarkdownTable();
  std::size_t rows = 0;
  for (char c : table) rows += c == '\n';
  EXPECT_EQ(rows, ekfParamRegistry().size() + 2);
  EXPECT_NE(table.find("| `pair_bias_tau_s` | `--pair-bias-tau-s` | s | `0` | ≥ 0 |"), std::string::npos) << table;
}

TEST(EkfParamRegistry, DocsTableIsTheGeneratedOne) {
  // GIVEN docs/parameters.md, THEN it holds the table `uwbtdoa params --markdown` prints (regenerate it after a change)
  std::ifstream in(std::string(UWB_SOURCE_DIR) + "/docs/parameters.md");
  ASSERT_TRUE(in) << "cannot read docs/parameters.md";
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find(ekfParamMarkdownTable()), std::string::npos)
      << "docs/parameters.md is out of date: regenerate its table with `uwbtdoa params --markdown`";
}

}  // namespace
}  // namespace uwb
