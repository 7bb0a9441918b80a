/** @file CsvDetail.cpp */
#include "CsvDetail.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <memory>

namespace uwb::io_detail {

namespace {
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
}  // namespace

std::string readWholeFile(const std::string& path, const char* what) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) throw FileError(fmt::format("cannot open {} '{}': {}", what, path, std::strerror(errno)));
  std::string text;
  if (std::fseek(f.get(), 0, SEEK_END) == 0) {
    const long size = std::ftell(f.get());
    if (size > 0) text.resize(static_cast<std::size_t>(size));
    std::rewind(f.get());
  }
  std::size_t got = text.empty() ? 0 : std::fread(text.data(), 1, text.size(), f.get());
  if (got < text.size()) text.resize(got);
  // Streams whose size is unknown (pipes) or that grew: read the rest in chunks.
  char buf[1 << 16];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f.get())) > 0;) text.append(buf, n);
  if (std::ferror(f.get())) throw FileError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
  return text;
}

void writeWholeFile(const std::string& path, std::string_view text, const char* what) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "wb"));
  if (!f) throw FileError(fmt::format("cannot create {} '{}': {}", what, path, std::strerror(errno)));
  if (std::fwrite(text.data(), 1, text.size(), f.get()) != text.size() || std::fflush(f.get()) != 0) {
    throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(errno)));
  }
}

}  // namespace uwb::io_detail
