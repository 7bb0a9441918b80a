/** @file Strings.h
 *  @brief Text helpers shared by the error messages of every module.
 */
#pragma once

#include <string>
#include <string_view>

namespace uwb {

/// Appends `item` to a comma-separated list ("a, b, c"): the lists of known names in error messages. Appending
/// in place (rather than `", " + item`, a prepend) also keeps GCC 12's link-time -Wstringop-overflow false positive
/// inside libstdc++'s string insert out of the build.
inline void appendToList(std::string* list, std::string_view item) {
  if (!list->empty()) list->append(", ");
  list->append(item);
}

}  // namespace uwb
