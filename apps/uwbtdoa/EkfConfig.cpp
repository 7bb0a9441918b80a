/** @file EkfConfig.cpp */
#include "EkfConfig.h"

#include <stdexcept>

#include "uwb/core/Error.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/io/JsonFile.h"

namespace uwb::app {

/// Reads the keys of a JSON object into EkfParams through the parameter registry (keys = field names; unknown keys,
/// values of the wrong kind and values outside their range are errors naming the file and the key; numbers are
/// range-checked before any conversion).
void applyEkfConfig(const nlohmann::json& j, const std::string& path, EkfParams& p) {
  const auto fail = [&](const std::string& key, const std::string& message) {
    throw InputError(SourceLocation{path, 0, 0, key}, message);
  };
  if (!j.is_object()) fail("", "expected a JSON object of EkfParams fields, got " + std::string(j.type_name()));
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& value = it.value();
    try {
      const EkfParamInfo& info = ekfParamInfo(key);
      EkfParamValue v;
      if (value.is_boolean()) v = value.get<bool>();
      else if (value.is_number()) v = jsonDouble(value, key);
      else if (value.is_string()) v = value.get<std::string>();
      else if (value.is_array() && value.size() == 3)
        v = Eigen::Vector3d(jsonDouble(value[0], key + "[0]"), jsonDouble(value[1], key + "[1]"),
                            jsonDouble(value[2], key + "[2]"));
      else v = value.dump();
      setEkfParam(p, info, v, "");
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      fail(key, e.what());
    }
  }
}

}  // namespace uwb::app
