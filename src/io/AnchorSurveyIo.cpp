/** @file AnchorSurveyIo.cpp
 *  @brief UTIL anchor survey text: `an{i}_p,x,y,z` [m] lines and `an{i}_quat,qx,qy,qz,qw` lines (docs/io.md).
 */
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <map>

#include "CsvDetail.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {

AnchorSurvey readAnchorSurvey(const std::string& path) {
  return parseAnchorSurvey(io_detail::readWholeFile(path, "anchor survey"), path);
}

namespace {

[[noreturn]] void failAt(const std::string& path, std::size_t line, std::size_t column, const std::string& field,
                         const std::string& msg) {
  throw InputError(SourceLocation{path, line, column, field}, msg);
}

/// A line's label: an<id>_p (position) or an<id>_quat (orientation).
struct SurveyLabel {
  int id = 0;
  bool is_quat = false;
};

SurveyLabel parseSurveyLabel(std::string_view label, const std::string& path, std::size_t line) {
  SurveyLabel out;
  const std::size_t us = label.rfind('_');
  if (label.size() < 4 || label.substr(0, 2) != "an" || us == std::string_view::npos || us <= 2) {
    failAt(path, line, 1, "", fmt::format("malformed survey line: expected 'an<id>_p' or 'an<id>_quat', got '{}'", label));
  }
  const std::string_view id_text = label.substr(2, us - 2);
  const auto [ptr, ec] = std::from_chars(id_text.data(), id_text.data() + id_text.size(), out.id);
  if (ec != std::errc() || ptr != id_text.data() + id_text.size() || out.id < 0 || out.id > kMaxAnchorId) {
    failAt(path, line, 1, "", fmt::format("malformed anchor id in '{}' (expected an integer in [0, {}])", label,
                                          kMaxAnchorId));
  }
  const std::string_view kind = label.substr(us + 1);
  if (kind == "p") {
    out.is_quat = false;
  } else if (kind == "quat") {
    out.is_quat = true;
  } else {
    failAt(path, line, 1, "", fmt::format("malformed survey line: unknown kind '{}' in '{}' (expected _p or _quat)",
                                          kind, label));
  }
  return out;
}

/// One anchor as it is read, with the lines that gave its position and orientation (0: not yet).
struct SurveyEntry {
  Anchor anchor;
  std::size_t p_line = 0;
  std::size_t q_line = 0;
};

/// Sets the position (v[0..2]) or the orientation (v = qx, qy, qz, qw) of an entry; each may be given once.
void setEntry(SurveyEntry& entry, const SurveyLabel& label, const double* v, std::string_view label_text,
              const std::string& path, std::size_t line) {
  const int id = label.id;
  entry.anchor.id = id;
  if (!label.is_quat) {
    if (entry.p_line != 0) {
      failAt(path, line, 1, std::string(label_text),
             fmt::format("duplicate anchor id {}: position already given on line {}", id, entry.p_line));
    }
    entry.p_line = line;
    entry.anchor.w_p = Vec3(v[0], v[1], v[2]);
  } else {
    if (entry.q_line != 0) {
      failAt(path, line, 1, std::string(label_text),
             fmt::format("duplicate anchor id {}: orientation already given on line {}", id, entry.q_line));
    }
    entry.q_line = line;
    entry.anchor.w_q = Quat(v[3], v[0], v[1], v[2]);
  }
}

}  // namespace

AnchorSurvey parseAnchorSurvey(std::string_view text, const std::string& path) {
  std::map<int, SurveyEntry> entries;
  io_detail::LineCursor lines(text);
  std::vector<std::string_view> cells;
  while (io_detail::nextCells(lines, cells, io_detail::HashComments::kSkip)) {
    const std::size_t line = lines.line();
    const std::string_view label = cells[0];
    const SurveyLabel parsed = parseSurveyLabel(label, path, line);
    const std::size_t n_expected = parsed.is_quat ? 5 : 4;
    if (cells.size() != n_expected) {
      failAt(path, line, std::min(cells.size(), n_expected) + 1, std::string(label),
             fmt::format("'{}' needs {} numbers, found {}", label, n_expected - 1, cells.size() - 1));
    }
    double v[4];
    for (std::size_t k = 1; k < n_expected; ++k) {
      const auto st = io_detail::parseDouble(cells[k].data(), cells[k].data() + cells[k].size(), v[k - 1]);
      if (st != io_detail::NumberStatus::kOk) {
        failAt(path, line, k + 1, std::string(label), fmt::format("{}: '{}'", io_detail::describe(st), cells[k]));
      }
    }
    setEntry(entries[parsed.id], parsed, v, label, path, line);
  }
  AnchorSurvey survey;
  survey.source = path;
  for (const auto& [id, entry] : entries) {
    if (entry.p_line == 0) {
      failAt(path, entry.q_line, 1, fmt::format("an{}_quat", id),
             fmt::format("missing position: anchor {} has an orientation but no 'an{}_p' line", id, id));
    }
    survey.anchors.push_back(entry.anchor);  // std::map: sorted by id
  }
  if (survey.anchors.empty()) failAt(path, std::max<std::size_t>(lines.line(), 1), 0, "", "survey holds no anchors");
  return survey;
}

void writeAnchorSurvey(const AnchorSurvey& survey, const std::string& path) {
  std::vector<Anchor> anchors = survey.anchors;
  std::sort(anchors.begin(), anchors.end(), [](const Anchor& a, const Anchor& b) { return a.id < b.id; });
  std::string out;
  for (const Anchor& a : anchors) {
    out += fmt::format("an{}_p,", a.id);
    io_detail::appendDouble(out, a.w_p.x());
    out.push_back(',');
    io_detail::appendDouble(out, a.w_p.y());
    out.push_back(',');
    io_detail::appendDouble(out, a.w_p.z());
    out.push_back('\n');
  }
  for (const Anchor& a : anchors) {
    out += fmt::format("an{}_quat,", a.id);
    const double q[4] = {a.w_q.x(), a.w_q.y(), a.w_q.z(), a.w_q.w()};
    for (int k = 0; k < 4; ++k) {
      if (k > 0) out.push_back(',');
      io_detail::appendDouble(out, q[k]);
    }
    out.push_back('\n');
  }
  io_detail::writeWholeFile(path, out, "anchor survey");
}

}  // namespace uwb
