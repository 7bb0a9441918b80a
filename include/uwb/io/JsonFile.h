/** @file JsonFile.h
 *  @brief Reading JSON files (bias models, configs) with errors that name the file, the line and the key, and
 *         value accessors that check type and range BEFORE converting (a 1e300 where an int is expected is an
 *         error, never a float-to-int overflow).
 */
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace uwb {

/// Deepest nesting of arrays and objects accepted in a JSON input (models and configs need fewer than 10 levels).
inline constexpr int kMaxJsonDepth = 64;

/// Byte offset of the first `[` or `{` (outside strings) that opens level max_depth + 1; npos when the text stays
/// within max_depth levels. Linear, no recursion: run before parsing untrusted text.
std::size_t jsonNestingTooDeepAt(std::string_view text, int max_depth = kMaxJsonDepth);

/// Parses the JSON file at `path` (read with readTextFile: directories and devices are refused).
/// FileError when it cannot be read; InputError "path:line:column: invalid JSON: ..." when it does not parse or
/// nests deeper than kMaxJsonDepth (checked before parsing).
nlohmann::json readJsonFile(const std::string& path, const char* what);
/// Same on text already in memory; `source` names it in messages.
nlohmann::json parseJsonText(std::string_view text, const std::string& source, const char* what);

/// Checked conversions. Each throws std::invalid_argument "'<key>' must be ..., got <value>" (the caller adds the
/// file); `key` is the path of the value in the document, e.g. "models[2].id_a".
double jsonDouble(const nlohmann::json& value, const std::string& key);
/// An integral number in [lo, hi]; 2.0 is accepted, 2.5, 1e300 and "2" are not.
long long jsonInteger(const nlohmann::json& value, const std::string& key, long long lo, long long hi);
int jsonInt(const nlohmann::json& value, const std::string& key, int lo, int hi);
std::string jsonString(const nlohmann::json& value, const std::string& key);
bool jsonBool(const nlohmann::json& value, const std::string& key);
/// The member `name` of the object `object` (std::invalid_argument "missing key '<key>.<name>'" when absent or
/// when `object` is not an object).
const nlohmann::json& jsonMember(const nlohmann::json& object, const std::string& key, const std::string& name);

}  // namespace uwb
