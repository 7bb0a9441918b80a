/** @file InputChecks.cpp */
#include "uwb/io/InputChecks.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "uwb/io/UtilCsv.h"

namespace uwb {

namespace {

InputIssue issue(IssueSeverity severity, const std::string& file, const std::string& field, std::string message) {
  return InputIssue{severity, SourceLocation{file, 0, 0, field}, std::move(message)};
}

/// Median spacing of consecutive stamps [s] (0 when fewer than two).
template <class Samples>
double medianSpacing(const Samples& samples) {
  if (samples.size() < 2) return 0.0;
  std::vector<double> dt;
  dt.reserve(samples.size() - 1);
  for (std::size_t i = 1; i < samples.size(); ++i) dt.push_back(samples[i].t_s - samples[i - 1].t_s);
  const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

template <class Samples>
double spanOf(const Samples& samples) {
  return samples.size() > 1 ? samples.back().t_s - samples.front().t_s : 0.0;
}

}  // namespace

SurveyGeometry surveyGeometry(const AnchorSurvey& survey) {
  SurveyGeometry g;
  g.n_anchors = survey.anchors.size();
  if (survey.anchors.empty()) return g;
  g.w_min = g.w_max = survey.anchors.front().w_p;
  for (const Anchor& a : survey.anchors) {
    g.w_centroid += a.w_p;
    g.w_min = g.w_min.cwiseMin(a.w_p);
    g.w_max = g.w_max.cwiseMax(a.w_p);
  }
  g.w_centroid /= static_cast<double>(survey.anchors.size());
  Mat3 scatter = Mat3::Zero();
  for (const Anchor& a : survey.anchors) {
    const Vec3 d = a.w_p - g.w_centroid;
    scatter += d * d.transpose();
  }
  scatter /= static_cast<double>(survey.anchors.size());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(scatter, Eigen::EigenvaluesOnly);
  const Vec3 ev = eig.eigenvalues().cwiseMax(0.0);  // ascending
  g.principal_std_m = Vec3(std::sqrt(ev(2)), std::sqrt(ev(1)), std::sqrt(ev(0)));
  return g;
}

std::vector<InputIssue> checkAnchorSeparation(const AnchorSurvey& survey, double min_separation_m) {
  std::vector<InputIssue> out;
  const auto& a = survey.anchors;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = i + 1; j < a.size(); ++j) {
      const double d = (a[i].w_p - a[j].w_p).norm();
      if (d < min_separation_m) {
        out.push_back(issue(IssueSeverity::kWarning, survey.source, "",
                            fmt::format("anchors {} and {} are {:.3f} m apart (< {} m): colocated, or one place "
                                        "surveyed twice; their TDoA carry almost no position information",
                                        a[i].id, a[j].id, d, min_separation_m)));
      }
    }
  }
  return out;
}

std::vector<InputIssue> checkSurveyGeometry(const AnchorSurvey& survey) {
  std::vector<InputIssue> out;
  const SurveyGeometry g = surveyGeometry(survey);
  const std::string& file = survey.source;
  const Vec3& s = g.principal_std_m;
  if (g.n_anchors < 2) {
    out.push_back(issue(IssueSeverity::kError, file, "", fmt::format("{} anchor(s): TDoA needs at least 2", g.n_anchors)));
    return out;
  }
  if (!(s(0) >= kMinAnchorSpread_m)) {
    out.push_back(issue(IssueSeverity::kError, file, "",
                        fmt::format("all {} anchors lie at (nearly) one point (spread {:.3g} m < {} m): no position can "
                                    "be computed from them; is this the right survey?",
                                    g.n_anchors, s(0), kMinAnchorSpread_m)));
    return out;
  }
  if (g.n_anchors >= 3 && !(s(1) >= kMinAnchorWidth_m)) {
    out.push_back(issue(IssueSeverity::kError, file, "",
                        fmt::format("the {} anchors lie on (nearly) one line (width {:.3g} m < {} m): the position "
                                    "across it cannot be computed",
                                    g.n_anchors, s(1), kMinAnchorWidth_m)));
    return out;
  }
  if (g.n_anchors < 4) {
    out.push_back(issue(IssueSeverity::kWarning, file, "",
                        fmt::format("only {} anchors: TDoA multilateration in 3-D needs at least 4", g.n_anchors)));
  } else if (!(s(2) >= kMinAnchorDepth_m)) {
    out.push_back(issue(IssueSeverity::kWarning, file, "",
                        fmt::format("the anchors are (nearly) coplanar (thickness {:.3g} m < {} m): the position "
                                    "normal to their plane is poorly observable",
                                    s(2), kMinAnchorDepth_m)));
  }
  const std::vector<InputIssue> close = checkAnchorSeparation(survey);
  out.insert(out.end(), close.begin(), close.end());
  if (s(0) > kMaxAnchorSpread_m) {
    // an error: no position found against such a survey means anything (a survey scaled ×1e9 put the estimate 1.5e9 m
    // up with exit 0)
    out.push_back(issue(IssueSeverity::kError, file, "",
                        fmt::format("the anchors spread over {:.3g} m (principal std), more than one UWB arena "
                                    "(< {} m): no position found against it would mean anything; are the coordinates "
                                    "in metres?",
                                    s(0), kMaxAnchorSpread_m)));
  }
  return out;
}

RateRange plausibleRate(Stream stream) {
  switch (stream) {
    case Stream::kAcc:
    case Stream::kGyro: return {20.0, 1e4};
    case Stream::kTdoa:
    case Stream::kTwr:
    case Stream::kPose: return {1.0, 1e4};
    default: return {0.2, 1e4};
  }
}

std::vector<InputIssue> checkStreamRates(const Flight& flight) {
  std::vector<InputIssue> out;
  const std::string& file = flight.source;
  const double tdoa_span_s = spanOf(flight.tdoa);
  const auto check = [&](Stream s, const auto& samples) {
    const std::string field = streamColumns(s).front();  // the stream's time column, e.g. t_acc
    const bool vital = s == Stream::kTdoa || s == Stream::kAcc || s == Stream::kGyro;
    const IssueSeverity severity = vital ? IssueSeverity::kError : IssueSeverity::kWarning;
    if (samples.size() >= 2 && samples.front().t_s == samples.back().t_s) {  // sorted: every stamp the same
      out.push_back(issue(severity, file, field,
                          fmt::format("stream {}: all {} time stamps are equal (t = {:g} s): the time column does not "
                                      "advance (a wrong column, or a logger that did not stamp)",
                                      streamName(s), samples.size(), samples.front().t_s)));
      return;
    }
    if (samples.size() < 10) return;
    if ((s == Stream::kAcc || s == Stream::kGyro) && flight.tdoa.size() >= 10 &&
        samples.back().t_s < flight.tdoa.back().t_s - kMaxImuEndGap_s) {
      out.push_back(issue(IssueSeverity::kWarning, file, field,
                          fmt::format("stream {} ends at t = {:.3f} s, {:.3f} s before the TDoA stream (t = {:.3f} s): "
                                      "the rest of the flight has no IMU",
                                      streamName(s), samples.back().t_s, flight.tdoa.back().t_s - samples.back().t_s,
                                      flight.tdoa.back().t_s)));
    }
    const double dt = medianSpacing(samples);
    const RateRange range = plausibleRate(s);
    const double span = spanOf(samples);
    if (dt > 0.0) {
      const double rate_hz = 1.0 / dt;
      if (rate_hz < range.min_hz || rate_hz > range.max_hz) {
        const char* hint = rate_hz < range.min_hz ? " (stamps in milliseconds instead of seconds?)"
                                                  : " (stamps in microseconds or ticks?)";
        out.push_back(issue(severity, file, field,
                            fmt::format("stream {}: median sample spacing {:.4g} s ({:.4g} Hz) is outside the plausible "
                                        "{:g}–{:g} Hz{}",
                                        streamName(s), dt, rate_hz, range.min_hz, range.max_hz, hint)));
        return;
      }
    }
    if (s != Stream::kTdoa && tdoa_span_s > 1.0 && span > 50.0 * tdoa_span_s) {
      out.push_back(issue(severity, file, field,
                          fmt::format("stream {} spans {:.4g} s but the TDoA stream {:.4g} s: the streams do not share "
                                      "one clock in seconds (stamps in milliseconds?)",
                                      streamName(s), span, tdoa_span_s)));
    }
  };
  check(Stream::kTdoa, flight.tdoa);
  check(Stream::kTwr, flight.twr);
  check(Stream::kAcc, flight.acc);
  check(Stream::kGyro, flight.gyro);
  check(Stream::kTof, flight.tof);
  check(Stream::kFlow, flight.flow);
  check(Stream::kBaro, flight.baro);
  check(Stream::kPose, flight.pose);
  return out;
}

bool hasError(const std::vector<InputIssue>& issues) {
  return std::any_of(issues.begin(), issues.end(), [](const InputIssue& i) { return i.severity == IssueSeverity::kError; });
}

void throwOnError(const std::vector<InputIssue>& issues) {
  const InputIssue* first = nullptr;
  std::string more;
  for (const InputIssue& i : issues) {
    if (i.severity != IssueSeverity::kError) continue;
    if (first == nullptr) {
      first = &i;
    } else {
      more += "\n  also: " + i.text();
    }
  }
  if (first != nullptr) throw InputError(first->where, first->message + more);
}

}  // namespace uwb
