/** @file CsvDetail.h
 *  @brief Internal helpers of the io module: whole-file reads, exact number parsing and shortest formatting.
 *
 *  Not a public header (lives in src/io): the readers parse with std::from_chars on one buffer, the writers
 *  format with std::to_chars (shortest representation that parses back to the same double).
 */
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "uwb/core/Error.h"

namespace uwb {
struct Flight;
enum class Stream;
}  // namespace uwb

namespace uwb::io_detail {

/// Whole file as one string; FileError when it cannot be opened or read, or is a directory or device
/// (uwb::readTextFile).
std::string readWholeFile(const std::string& path, const char* what);
/// Writes `text` to `path` atomically (uwb::writeFileAtomically); FileError on failure.
void writeWholeFile(const std::string& path, std::string_view text, const char* what);

inline bool isBlank(char c) { return c == ' ' || c == '\t'; }

/// Trims spaces and tabs on both sides of [b, e).
inline void trim(const char*& b, const char*& e) {
  while (b < e && isBlank(*b)) ++b;
  while (e > b && isBlank(e[-1])) --e;
}

/// Walks a text buffer line by line for the readers: skips a leading UTF-8 byte-order mark, strips the '\r' of
/// CRLF line ends, and counts lines from 1 so that errors can name them.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : p_(text.data()), end_(text.data() + text.size()) {
    if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) p_ += 3;
  }
  /// The next line as [b, e), without its line end; false when the text is exhausted.
  bool next(const char*& b, const char*& e) {
    if (p_ >= end_) return false;
    b = p_;
    const void* nl = std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_));
    e = nl != nullptr ? static_cast<const char*>(nl) : end_;
    p_ = nl != nullptr ? e + 1 : end_;
    if (e > b && e[-1] == '\r') --e;
    ++line_;
    return true;
  }
  /// 1-based number of the line last returned by next() (0 before the first).
  std::size_t line() const { return line_; }
  /// The text not yet returned.
  std::string_view rest() const { return {p_, static_cast<std::size_t>(end_ - p_)}; }

 private:
  const char* p_;
  const char* end_;
  std::size_t line_ = 0;
};

/// The one cell splitter of the readers: calls `cell(index, begin, end)` for each comma-separated cell of [b, e),
/// trimmed of spaces and tabs, and returns the number of cells. Cells are short (≤ 12 characters in UTIL files):
/// a plain scan beats one memchr call per cell.
template <class Cell>
std::size_t forEachCell(const char* b, const char* e, Cell&& cell) {
  std::size_t n = 0;
  for (const char* c = b;;) {
    const char* end = c;
    while (end < e && *end != ',') ++end;
    const char* tb = c;
    const char* te = end;
    trim(tb, te);
    cell(n, tb, te);
    ++n;
    if (end == e) return n;
    c = end + 1;
  }
}

/// Splits [b, e) at commas into cells trimmed of spaces and tabs (replaces the contents of `cells`).
inline void splitCells(const char* b, const char* e, std::vector<std::string_view>& cells) {
  cells.clear();
  forEachCell(b, e, [&](std::size_t, const char* tb, const char* te) {
    cells.emplace_back(tb, static_cast<std::size_t>(te - tb));
  });
}

/// The number of samples of one stream of the flight (UtilCsv.cpp).
std::size_t streamSize(const Flight& flight, Stream stream);

/// Whether a line that starts with '#' is a comment (skipped) or data.
enum class HashComments { kData, kSkip };

/// Advances `lines` to the next line that is not blank after trimming (nor a '#' comment with kSkip) and splits it
/// into `cells`; false at the end of the text. lines.line() is then the number of that line.
inline bool nextCells(LineCursor& lines, std::vector<std::string_view>& cells, HashComments comments) {
  const char* b = nullptr;
  const char* e = nullptr;
  while (lines.next(b, e)) {
    trim(b, e);
    if (b == e || (comments == HashComments::kSkip && *b == '#')) continue;  // blank lines (and comments)
    splitCells(b, e, cells);
    return true;
  }
  return false;
}

enum class NumberStatus { kOk, kNotANumber, kOutOfRange, kNonFinite };

/// Clinger's fast path: a plain decimal `[-]digits[.digits][e[+-]digits]` with at most 19 significant digits,
/// significand ≤ 2^53 and |power of ten| ≤ 22 is exactly w · 10^q or w / 10^-q, one correctly rounded IEEE
/// operation on two exact doubles, so the result equals std::from_chars bit for bit. Returns false (caller falls
/// back to from_chars) for anything else.
inline bool parseDecimalFast(const char* p, const char* e, double& out) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  bool negative = false;
  if (p < e && *p == '-') {
    negative = true;
    ++p;
  }
  std::uint64_t w = 0;
  int significant = 0;
  int fraction_digits = 0;
  bool any_digit = false;
  const auto digit = [&](unsigned d) -> bool {
    if (w != 0 || d != 0) {
      if (++significant > 19) return false;
    }
    w = w * 10 + d;
    any_digit = true;
    return true;
  };
  for (; p < e && static_cast<unsigned>(*p - '0') < 10; ++p) {
    if (!digit(static_cast<unsigned>(*p - '0'))) return false;
  }
  if (p < e && *p == '.') {
    ++p;
    for (; p < e && static_cast<unsigned>(*p - '0') < 10; ++p) {
      if (!digit(static_cast<unsigned>(*p - '0'))) return false;
      ++fraction_digits;
    }
  }
  if (!any_digit) return false;
  int exponent = 0;
  if (p < e && (*p == 'e' || *p == 'E')) {
    ++p;
    bool exp_negative = false;
    if (p < e && (*p == '-' || *p == '+')) exp_negative = *p++ == '-';
    if (p == e) return false;
    for (; p < e && static_cast<unsigned>(*p - '0') < 10; ++p) {
      exponent = exponent * 10 + (*p - '0');
      if (exponent > 1000) return false;
    }
    if (exp_negative) exponent = -exponent;
  }
  if (p != e) return false;
  const int q = exponent - fraction_digits;
  if (w > (std::uint64_t{1} << 53) || q < -22 || q > 22) return false;
  const double value = q < 0 ? static_cast<double>(w) / kPow10[-q] : static_cast<double>(w) * kPow10[q];
  out = negative ? -value : value;
  return true;
}

/// Parses the whole of [b, e) (already trimmed) as a double. A leading '+' is accepted.
inline NumberStatus parseDouble(const char* b, const char* e, double& out) {
  if (b < e && *b == '+') ++b;
  if (b == e) return NumberStatus::kNotANumber;
  if (parseDecimalFast(b, e, out)) return NumberStatus::kOk;
  const auto [p, ec] = std::from_chars(b, e, out, std::chars_format::general);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || p != e) return NumberStatus::kNotANumber;
  if (!std::isfinite(out)) return NumberStatus::kNonFinite;
  return NumberStatus::kOk;
}

inline const char* describe(NumberStatus s) {
  switch (s) {
    case NumberStatus::kOk: return "ok";
    case NumberStatus::kNotANumber: return "not a number";
    case NumberStatus::kOutOfRange: return "number out of range";
    case NumberStatus::kNonFinite: return "NaN or Inf is not allowed";
  }
  return "?";
}

/// Appends the shortest decimal that parses back to exactly x.
inline void appendDouble(std::string& out, double x) {
  char buf[32];
  const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, p);
}

inline void appendInt(std::string& out, long long x) {
  char buf[24];
  const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, p);
}

/// The double d (closest to x/scale) such that d * scale == x exactly, so that a value read as
/// parse(text) * scale is written back as text that reproduces it bit for bit. Falls back to x/scale when no
/// such d exists within a few ulps (x did not come from a file).
inline double unscaleExactly(double x, double scale) {
  const double y = x / scale;
  if (y * scale == x) return y;
  double up = y, down = y;
  for (int k = 0; k < 8; ++k) {
    up = std::nextafter(up, INFINITY);
    if (up * scale == x) return up;
    down = std::nextafter(down, -INFINITY);
    if (down * scale == x) return down;
  }
  return y;
}

}  // namespace uwb::io_detail
