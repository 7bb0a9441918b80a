/** @file FuzzInput.h
 *  @brief Shared by the harnesses: what a reader may do with a crafted input. It may accept it or reject it with
 *         the library's documented exceptions (InputError, FileError, std::invalid_argument for a model or config
 *         that parses but is inconsistent); anything else (a crash, a sanitizer report, std::bad_alloc, a
 *         std::logic_error from UWB_ASSERT, another exception) is a finding.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "uwb/core/Error.h"

namespace uwb::fuzz {

inline std::string_view asText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Runs `read`; swallows the exceptions a reader documents for bad input, lets every other one escape (libFuzzer
/// then reports the input as a crash).
template <class F>
void expectCleanRejection(F&& read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const FileError&) {
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace uwb::fuzz
