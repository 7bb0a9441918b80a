/** @file EkfParamRegistry.h
 *  @brief One registry of the EkfParams fields (the Crazyflie `param` idea): each field once, with its name, unit,
 *         documentation, valid range and getter/setter. It drives every way of setting the filter's parameters —
 *         the CLI flags of `uwbtdoa localize`, the `--config` file, Python's `params=` dict — their validation and
 *         the generated table docs/parameters.md (`uwbtdoa params --markdown`).
 *
 *  Adding a field to EkfParams is one line in src/filter/EkfParamRegistry.cpp (a test fails until it is there).
 *  Names are the struct fields (those of the nested flight_mode with the prefix mode_); the CLI flag is the name with
 *  '-' for '_' (`--tdoa-sigma-m`), plus an optional short alias (`--tdoa-sigma`).
 */
#pragma once

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/filter/EkfParams.h"

namespace uwb {

enum class EkfParamKind {
  kReal,     ///< double
  kInteger,  ///< int
  kBool,     ///< bool
  kVec3,     ///< three numbers x, y, z
  kChoice,   ///< one of a list of names (an enum)
};

/// A parameter value of any kind (integers travel as double and must be whole).
using EkfParamValue = std::variant<double, bool, Vec3, std::string>;

/// Valid interval of a real or integer parameter (non-finite values are never valid).
struct EkfParamRange {
  double lo = -1e308;
  double hi = 1e308;
  bool lo_open = false;  ///< lo itself is excluded
  bool hi_open = false;
  bool contains(double v) const;
  std::string toString() const;  ///< "> 0", "≥ 0", "[1, 20]", "finite"
};

struct EkfParamInfo {
  std::string name;       ///< struct field, config key and Python key
  std::string cli_alias;  ///< extra CLI flag without dashes ("tdoa-sigma"), or empty
  std::string cli_negation;  ///< kBool: a CLI flag without dashes that sets it false ("no-tof"), or empty
  std::string unit;       ///< SI unit ("m", "m/s^2/sqrt(Hz)"), empty when dimensionless
  std::string doc;        ///< one sentence
  EkfParamKind kind = EkfParamKind::kReal;
  EkfParamRange range;               ///< kReal, kInteger
  std::vector<std::string> choices;  ///< kChoice
  std::function<EkfParamValue(const EkfParams&)> get;
  std::function<void(EkfParams&, const EkfParamValue&)> set;  ///< no checks: use setEkfParam

  std::string flag() const;  ///< "--" + name with '-' for '_'
};

/// Every field of EkfParams, in the order of the struct.
const std::vector<EkfParamInfo>& ekfParamRegistry();
/// The entry of `name` (a struct field name); throws std::invalid_argument listing the known names.
const EkfParamInfo& ekfParamInfo(const std::string& name);

/// Checks `value` against the entry (kind, range, choices) and sets it; throws std::invalid_argument
/// "<where>: <name> must be … (got …)" — `where` names the source (a flag, "params"; empty: no prefix).
void setEkfParam(EkfParams& p, const EkfParamInfo& info, const EkfParamValue& value, const std::string& where);
/// Parses text as the CLI gives it ("0.3", "true", "1,2,3", "huber") and sets it, with the same checks.
void setEkfParamFromText(EkfParams& p, const EkfParamInfo& info, const std::string& text, const std::string& where);

/// The value as text, in the form setEkfParamFromText reads ("0.35", "true", "0,0,0.05", "thrust").
std::string ekfParamText(const EkfParams& p, const EkfParamInfo& info);
/// The unit in brackets and the default of a fresh EkfParams, for help texts: "[m] (default 0.35, > 0)".
std::string ekfParamHelpSuffix(const EkfParamInfo& info);

/// Every range and choice of the registry; throws std::invalid_argument naming the first offending field.
void validateEkfParamRanges(const EkfParams& p);

/// The table of docs/parameters.md: name, CLI flag, unit, default, range, description.
std::string ekfParamMarkdownTable();

}  // namespace uwb
