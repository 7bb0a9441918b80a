/** @file CsvDetail.cpp */
#include "CsvDetail.h"

#include "uwb/io/FileAccess.h"

namespace uwb::io_detail {

std::string readWholeFile(const std::string& path, const char* what) { return readTextFile(path, what); }

void writeWholeFile(const std::string& path, std::string_view text, const char* what) {
  writeFileAtomically(path, text, what);
}

}  // namespace uwb::io_detail
