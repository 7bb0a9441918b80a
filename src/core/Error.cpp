/** @file Error.cpp */
#include "uwb/core/Error.h"

#include <fmt/format.h>

namespace uwb {

std::string SourceLocation::toString() const {
  std::string out = file.empty() ? std::string("<input>") : file;
  if (line > 0) out += fmt::format(":{}", line);
  if (column > 0) out += fmt::format(":{}", column);
  if (!field.empty()) out += fmt::format(" ({})", field);
  return out;
}

InputError::InputError(SourceLocation where, const std::string& what)
    : std::runtime_error(where.toString() + ": " + what), where_(std::move(where)) {}

}  // namespace uwb
