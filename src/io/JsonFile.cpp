/** @file JsonFile.cpp */
#include "uwb/io/JsonFile.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"

namespace uwb {

namespace {

/// A short rendering of a JSON value for messages (long arrays and objects are cut).
std::string shortDump(const nlohmann::json& v) {
  std::string s = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

/// The library's parse-error text without its "[json.exception.parse_error.101] parse error at line 1, column 2: "
/// prefix (the location is reported separately).
std::string parseMessage(const nlohmann::json::parse_error& e) {
  std::string msg = e.what();
  const std::size_t col = msg.find("column ");
  const std::size_t colon = col == std::string::npos ? msg.find(": ") : msg.find(": ", col);
  if (colon != std::string::npos) msg = msg.substr(colon + 2);
  return msg;
}

/// Line and column (1-based) of byte `at` of `text`.
std::pair<std::size_t, std::size_t> lineColumn(std::string_view text, std::size_t at) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < at && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

}  // namespace

std::size_t jsonNestingTooDeepAt(std::string_view text, int max_depth) {
  // A scan of the brackets outside strings, before the parser sees the text: nothing deeper than max_depth is ever
  // built, dumped or destroyed recursively.
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    }
  }
  return std::string_view::npos;
}

nlohmann::json readJsonFile(const std::string& path, const char* what) {
  return parseJsonText(readTextFile(path, what), path, what);
}

nlohmann::json parseJsonText(std::string_view text, const std::string& path, const char* what) {
  if (const std::size_t at = jsonNestingTooDeepAt(text); at != std::string_view::npos) {
    const auto [line, column] = lineColumn(text, at);
    throw InputError(SourceLocation{path, line, column, ""},
                     fmt::format("invalid JSON in {}: nested deeper than {} levels of arrays and objects", what,
                                 kMaxJsonDepth));
  }
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte: 1-based offset of the character where parsing stopped; turn it into line and column.
    const auto [line, column] = lineColumn(text, std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size()));
    throw InputError(SourceLocation{path, line, column, ""}, fmt::format("invalid JSON in {}: {}", what, parseMessage(e)));
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range: a number such as 1e400
    std::string msg = e.what();
    const std::size_t bracket = msg.find("] ");
    if (bracket != std::string::npos) msg = msg.substr(bracket + 2);
    throw InputError(SourceLocation{path, 0, 0, ""}, fmt::format("invalid JSON in {}: {}", what, msg));
  }
}

double jsonDouble(const nlohmann::json& value, const std::string& key) {
  if (!value.is_number()) throw std::invalid_argument(fmt::format("'{}' must be a number, got {}", key, shortDump(value)));
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw std::invalid_argument(fmt::format("'{}' must be a finite number, got {}", key, shortDump(value)));
  return x;
}

long long jsonInteger(const nlohmann::json& value, const std::string& key, long long lo, long long hi) {
  const auto bad = [&]() {
    return std::invalid_argument(fmt::format("'{}' must be an integer in [{}, {}], got {}", key, lo, hi, shortDump(value)));
  };
  if (value.is_number_unsigned()) {
    const auto u = value.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(hi) || (lo > 0 && u < static_cast<std::uint64_t>(lo))) throw bad();
    return static_cast<long long>(u);
  }
  if (value.is_number_integer()) {
    const auto i = value.get<std::int64_t>();
    if (i < lo || i > hi) throw bad();
    return i;
  }
  if (value.is_number_float()) {
    const double x = value.get<double>();
    // Compare as doubles first: converting an out-of-range double to an integer is undefined behaviour.
    if (!std::isfinite(x) || x != std::floor(x) || x < static_cast<double>(lo) || x > static_cast<double>(hi)) throw bad();
    return static_cast<long long>(x);
  }
  throw bad();
}

int jsonInt(const nlohmann::json& value, const std::string& key, int lo, int hi) {
  return static_cast<int>(jsonInteger(value, key, lo, hi));
}

std::string jsonString(const nlohmann::json& value, const std::string& key) {
  if (!value.is_string()) throw std::invalid_argument(fmt::format("'{}' must be a string, got {}", key, shortDump(value)));
  return value.get<std::string>();
}

bool jsonBool(const nlohmann::json& value, const std::string& key) {
  if (!value.is_boolean()) throw std::invalid_argument(fmt::format("'{}' must be true or false, got {}", key, shortDump(value)));
  return value.get<bool>();
}

const nlohmann::json& jsonMember(const nlohmann::json& object, const std::string& key, const std::string& name) {
  const std::string full = key.empty() ? name : key + "." + name;
  if (!object.is_object()) throw std::invalid_argument(fmt::format("'{}' must be an object", key.empty() ? "(top level)" : key));
  const auto it = object.find(name);
  if (it == object.end()) throw std::invalid_argument(fmt::format("missing key '{}'", full));
  return *it;
}

}  // namespace uwb
