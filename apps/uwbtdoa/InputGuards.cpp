/** @file InputGuards.cpp */
#include "InputGuards.h"

#include <fmt/format.h>

#include <cmath>
#include <iostream>

#include "uwb/core/Error.h"

namespace uwb::app {

void Warnings::add(const std::string& text) {
  std::cerr << "uwbtdoa: warning: " << text << '\n';
  list_.push_back(text);
}

void Warnings::addIssues(const std::vector<InputIssue>& issues) {
  throwOnError(issues);
  for (const InputIssue& i : issues) add(i.text());
}

std::string dumpJson(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

void checkNearAnchors(const Vec3& w_p, const AnchorSurvey& survey, const std::string& option, double margin_m) {
  if (!w_p.allFinite()) throw InputError(fmt::format("{}: the position must be finite", option));
  const SurveyGeometry g = surveyGeometry(survey);
  const Vec3 outside = (g.w_min - w_p).cwiseMax(w_p - g.w_max).cwiseMax(0.0);
  if (outside.norm() > margin_m) {
    throw InputError(fmt::format(
        "{} ({:g}, {:g}, {:g}) m lies {:.4g} m outside the anchors' box [{:.3g}, {:.3g}] x [{:.3g}, {:.3g}] x "
        "[{:.3g}, {:.3g}] m of {} (at most {:g} m allowed)",
        option, w_p.x(), w_p.y(), w_p.z(), outside.norm(), g.w_min.x(), g.w_max.x(), g.w_min.y(), g.w_max.y(),
        g.w_min.z(), g.w_max.z(), survey.source.empty() ? "the survey" : survey.source, margin_m));
  }
}

void checkPeriod(double value_s, const std::string& option, double max_s) {
  if (!std::isfinite(value_s) || !(value_s > 0.0) || value_s > max_s) {
    throw InputError(fmt::format("{} must be a finite number of seconds in (0, {:g}], got {}", option, max_s, value_s));
  }
}

nlohmann::json sensorRangeJson(const SensorRangeReport& report) {
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const auto one = [&](const SensorRangeCount& c) {
    return nlohmann::json{{"n", c.n}, {"limit", num(c.limit)}, {"first_t_s", c.n ? num(c.first_t_s) : nullptr},
                          {"worst", c.n ? num(c.worst) : nullptr}};
  };
  return {{"gyro", one(report.gyro)}, {"acc", one(report.acc)}, {"tdoa", one(report.tdoa)}};
}

}  // namespace uwb::app
