/** @file Error.h
 *  @brief Exceptions of the library. Input problems carry file, line and column so a user can fix them.
 *
 *  - InputError: malformed or inconsistent data (maps to Python ValueError).
 *  - FileError: a file that cannot be opened, read or written (maps to Python OSError).
 *  Programmer errors at public boundaries throw std::invalid_argument.
 */
#pragma once

#include <stdexcept>
#include <string>

namespace uwb {

/// Location of a problem in a text file: 1-based line and column; 0 means "not applicable".
struct SourceLocation {
  std::string file;
  std::size_t line = 0;
  std::size_t column = 0;
  std::string field;  ///< column name (e.g. "tdoa_meas"), if known

  /// "file:line:column (field)" with the parts that are known.
  std::string toString() const;
};

/// Bad input data: the message starts with the location ("flight.csv:17:4 (tdoa_meas): ...").
class InputError : public std::runtime_error {
 public:
  InputError(SourceLocation where, const std::string& what);
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
  const SourceLocation& where() const { return where_; }

 private:
  SourceLocation where_;
};

/// A file that cannot be opened, read or written.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace uwb
