/** @file SurveyCheck.cpp
 *  @brief cfclient anchor-position YAML → survey, and the survey checks (io/SurveyCheck.h).
 */
#include "uwb/io/SurveyCheck.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "CsvDetail.h"
#include "uwb/core/Error.h"

namespace uwb {

namespace {

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string_view unquoted(std::string_view s) {
  if (s.size() >= 2 && (s.front() == '\'' || s.front() == '"') && s.back() == s.front()) return s.substr(1, s.size() - 2);
  return s;
}

/// The text before a YAML comment (`#` at the start or after a blank).
std::string_view withoutComment(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s[i] == '#' && (i == 0 || s[i - 1] == ' ' || s[i - 1] == '\t')) return s.substr(0, i);
  return s;
}

class CfclientParser {
 public:
  CfclientParser(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  AnchorSurvey run() {
    io_detail::LineCursor lines(text_);
    const char* b = nullptr;
    const char* e = nullptr;
    while (lines.next(b, e)) {
      line_ = lines.line();
      const std::string_view raw(b, static_cast<std::size_t>(e - b));
      const std::string_view s = trimmed(withoutComment(raw));
      if (s.empty() || s == "---" || s == "..." || s.front() == '%') continue;
      const bool indented = raw.front() == ' ' || raw.front() == '\t';
      const std::size_t colon = s.find(':');
      if (colon == std::string_view::npos) fail(1, "", fmt::format("expected 'key: value', got '{}'", s));
      const std::string_view key = unquoted(trimmed(s.substr(0, colon)));
      const std::string_view value = trimmed(s.substr(colon + 1));
      if (!indented) {
        finishAnchor();
        startAnchor(key);
        if (!value.empty()) flowMapping(value);
      } else {
        if (!current_) fail(1, std::string(key), "indented coordinate before any anchor id");
        coordinate(key, value, indentOf(raw) + 1);
      }
    }
    finishAnchor();
    if (anchors_.empty()) {
      line_ = std::max<std::size_t>(lines.line(), 1);
      fail(0, "", "no anchor in the file; expected cfclient's anchor positions ('0: {x: 0.0, y: 0.0, z: 0.0}' or "
                  "'0:' then indented 'x: …', 'y: …', 'z: …')");
    }
    AnchorSurvey survey;
    survey.source = source_;
    for (const auto& [id, a] : anchors_) survey.anchors.push_back(a);
    return survey;
  }

 private:
  struct Pending {
    Anchor anchor;
    std::size_t line = 0;
    bool has[3] = {false, false, false};
  };

  [[noreturn]] void fail(std::size_t column, const std::string& field, const std::string& what) const {
    throw InputError(SourceLocation{source_, line_, column, field}, what);
  }

  static std::size_t indentOf(std::string_view raw) {
    std::size_t i = 0;
    while (i < raw.size() && (raw[i] == ' ' || raw[i] == '\t')) ++i;
    return i;
  }

  void startAnchor(std::string_view key) {
    int id = -1;
    const auto [ptr, ec] = std::from_chars(key.data(), key.data() + key.size(), id);
    if (ec != std::errc() || ptr != key.data() + key.size() || id < 0 || id > kMaxAnchorId) {
      fail(1, "", fmt::format("anchor id must be an integer in [0, {}], got '{}'", kMaxAnchorId, key));
    }
    if (const auto it = anchors_.find(id); it != anchors_.end()) {
      fail(1, "", fmt::format("duplicate anchor id {}: already given on line {}", id, lines_.at(id)));
    }
    current_ = Pending{};
    current_->anchor.id = id;
    current_->line = line_;
  }

  void coordinate(std::string_view key, std::string_view value, std::size_t column) {
    const int axis = key == "x" ? 0 : key == "y" ? 1 : key == "z" ? 2 : -1;
    const std::string field = fmt::format("anchor {}", current_->anchor.id);
    if (axis < 0) fail(column, field, fmt::format("unknown key '{}' (an anchor has x, y, z)", key));
    if (current_->has[axis]) fail(column, field, fmt::format("'{}' given twice", key));
    double v = 0.0;
    const std::string_view text = unquoted(value);
    const auto st = io_detail::parseDouble(text.data(), text.data() + text.size(), v);
    if (st != io_detail::NumberStatus::kOk || !std::isfinite(v)) {
      fail(column, field, fmt::format("{} must be a finite number in metres, got '{}'", key, value));
    }
    current_->anchor.w_p(axis) = v;
    current_->has[axis] = true;
  }

  /// `{x: 1.0, y: 2.0, z: 3.0}`
  void flowMapping(std::string_view value) {
    if (value.size() < 2 || value.front() != '{' || value.back() != '}') {
      fail(1, fmt::format("anchor {}", current_->anchor.id),
           fmt::format("expected '{{x: …, y: …, z: …}}' or a line break after the id, got '{}'", value));
    }
    std::string_view body = value.substr(1, value.size() - 2);
    while (!trimmed(body).empty()) {
      const std::size_t comma = body.find(',');
      const std::string_view item = trimmed(body.substr(0, comma));
      const std::size_t colon = item.find(':');
      if (colon == std::string_view::npos) {
        fail(1, fmt::format("anchor {}", current_->anchor.id), fmt::format("expected 'key: value', got '{}'", item));
      }
      coordinate(unquoted(trimmed(item.substr(0, colon))), trimmed(item.substr(colon + 1)), 1);
      if (comma == std::string_view::npos) break;
      body.remove_prefix(comma + 1);
    }
  }

  void finishAnchor() {
    if (!current_) return;
    for (int k = 0; k < 3; ++k) {
      if (!current_->has[k]) {
        line_ = current_->line;
        fail(1, fmt::format("anchor {}", current_->anchor.id),
             fmt::format("anchor {} has no '{}' coordinate", current_->anchor.id, "xyz"[k]));
      }
    }
    lines_[current_->anchor.id] = current_->line;
    anchors_[current_->anchor.id] = current_->anchor;
    current_.reset();
  }

  std::string_view text_;
  std::string source_;
  std::size_t line_ = 0;
  std::optional<Pending> current_;
  std::map<int, Anchor> anchors_;
  std::map<int, std::size_t> lines_;
};

InputIssue warning(const std::string& file, const std::string& message) {
  InputIssue i;
  i.severity = IssueSeverity::kWarning;
  i.where.file = file;
  i.message = message;
  return i;
}

}  // namespace

AnchorSurvey parseCfclientAnchors(std::string_view text, const std::string& source) {
  return CfclientParser(text, source).run();
}

AnchorSurvey readCfclientAnchors(const std::string& path) {
  return parseCfclientAnchors(io_detail::readWholeFile(path, "anchor positions"), path);
}

std::string formatCfclientAnchors(const AnchorSurvey& survey) {
  std::string out;
  for (const Anchor& a : survey.anchors) {
    out += fmt::format("{}:\n", a.id);
    for (int k = 0; k < 3; ++k) {
      out += fmt::format("  {}: ", "xyz"[k]);
      io_detail::appendDouble(out, a.w_p(k));
      out.push_back('\n');
    }
  }
  return out;
}

std::vector<InputIssue> checkAnchorPlane(const AnchorSurvey& survey) {
  std::vector<InputIssue> out;
  const std::size_t n = survey.anchors.size();
  if (n < 4) return out;
  Vec3 mean = Vec3::Zero();
  for (const Anchor& a : survey.anchors) mean += a.w_p;
  mean /= static_cast<double>(n);
  Mat3 cov = Mat3::Zero();
  for (const Anchor& a : survey.anchors) cov += (a.w_p - mean) * (a.w_p - mean).transpose();
  cov /= static_cast<double>(n);
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  Vec3 normal = eig.eigenvectors().col(0);  // smallest eigenvalue first
  int largest = 0;
  normal.cwiseAbs().maxCoeff(&largest);
  if (normal(largest) < 0.0) normal = -normal;  // a sign that does not depend on the solver
  double thickness_m = 0.0;  // largest distance of an anchor from the plane
  for (const Anchor& a : survey.anchors) thickness_m = std::max(thickness_m, std::abs(normal.dot(a.w_p - mean)));
  if (!(std::sqrt(std::max(0.0, eig.eigenvalues()(0))) < kMinAnchorDepth_m)) return out;
  const double vertical = std::abs(normal.z());
  if (vertical > std::cos(20.0 * kDegToRad)) {
    out.push_back(warning(survey.source,
                          fmt::format("all {} anchors lie within {:.2f} m of one horizontal plane (z ≈ {:.2f} m): the "
                                      "vertical (z) is poorly observable from their TDoA; mount about half of them "
                                      "low and half high (1 m or more apart in height), or fuse a height sensor "
                                      "(--fuse-tof)",
                                      n, thickness_m, mean.z())));
  } else {
    out.push_back(warning(survey.source,
                          fmt::format("all {} anchors lie within {:.2f} m of one plane (normal {:.2f}, {:.2f}, {:.2f}): "
                                      "the position along that normal is poorly observable from their TDoA; move "
                                      "some anchors out of the plane",
                                      n, thickness_m, normal.x(), normal.y(), normal.z())));
  }
  return out;
}

std::vector<InputIssue> checkFlightAnchorIds(const AnchorSurvey& survey, const Flight& flight) {
  std::map<int, std::size_t> count;
  for (const TdoaMeasurement& m : flight.tdoa) {
    ++count[m.id_a];
    ++count[m.id_b];
  }
  for (const TwrMeasurement& m : flight.twr) ++count[m.anchor_id];
  std::vector<InputIssue> out;
  for (const auto& [id, n] : count) {
    if (survey.contains(id)) continue;
    out.push_back(warning(flight.source,
                          fmt::format("anchor {} is in {} of the flight's {} TDoA (and TWR) but not in the survey {}: "
                                      "those measurements are ignored; add its position",
                                      id, n, flight.tdoa.size() + flight.twr.size(), survey.source)));
  }
  return out;
}

std::vector<InputIssue> checkFlightInsideAnchors(const AnchorSurvey& survey, const std::vector<Vec3>& w_p_flight,
                                                 const std::string& source) {
  std::vector<InputIssue> out;
  if (survey.anchors.empty() || w_p_flight.empty()) return out;
  Vec3 lo = survey.anchors.front().w_p, hi = lo;
  for (const Anchor& a : survey.anchors) {
    lo = lo.cwiseMin(a.w_p);
    hi = hi.cwiseMax(a.w_p);
  }
  std::size_t outside = 0;
  double worst_m = 0.0;
  int worst_axis = 0;
  for (const Vec3& p : w_p_flight) {
    const Vec3 excess = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
    int axis = 0;
    const double e = excess.maxCoeff(&axis);
    if (e > kFlightOutsideMargin_m) ++outside;
    if (e > worst_m) {
      worst_m = e;
      worst_axis = axis;
    }
  }
  const double share = static_cast<double>(outside) / static_cast<double>(w_p_flight.size());
  if (share > kMaxShareOutside) {
    out.push_back(warning(
        source, fmt::format("{:.1f} % of the flight's {} positions lie outside the anchors' box (x {:.2f}…{:.2f}, y "
                            "{:.2f}…{:.2f}, z {:.2f}…{:.2f} m) by more than {} m, up to {:.2f} m along {}: the "
                            "anchors do not surround the flight and the TDoA geometry degrades there",
                            100.0 * share, w_p_flight.size(), lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z(),
                            kFlightOutsideMargin_m, worst_m, "xyz"[worst_axis])));
  }
  return out;
}

std::vector<InputIssue> checkSurvey(const AnchorSurvey& survey, const Flight* flight,
                                    const std::vector<Vec3>& w_p_flight, const std::string& positions_source) {
  std::vector<InputIssue> out = checkSurveyGeometry(survey);
  std::erase_if(out, [](const InputIssue& i) {  // the plane check below says which axis and how to fix it
    return i.severity == IssueSeverity::kWarning && i.message.find("coplanar") != std::string::npos;
  });
  const auto add = [&](const std::vector<InputIssue>& v) { out.insert(out.end(), v.begin(), v.end()); };
  add(checkAnchorPlane(survey));
  if (flight != nullptr) add(checkFlightAnchorIds(survey, *flight));
  add(checkFlightInsideAnchors(survey, w_p_flight, positions_source));
  return out;
}

}  // namespace uwb
