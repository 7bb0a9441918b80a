/** @file EstimateFormat.cpp
 *  @brief JSON-lines and CSV text of an estimate, and reading it back (docs/io.md §5).
 */
#include "uwb/stream/EstimateFormat.h"

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "uwb/core/Error.h"

namespace uwb {
namespace {

/// Shortest round-trip text; JSON has no NaN/∞, so those are written as null (CSV: nan/inf).
void appendNumber(std::string& out, double v, EstimateFormat format) {
  if (format == EstimateFormat::kJson && !std::isfinite(v)) {
    out += "null";
    return;
  }
  fmt::format_to(std::back_inserter(out), "{}", v);
}

FlightPhase phaseFromString(const std::string& s, std::size_t line_no) {
  for (FlightPhase p : {FlightPhase::kGround, FlightPhase::kAcquisition, FlightPhase::kTracking, FlightPhase::kLanded})
    if (toString(p) == s) return p;
  throw InputError(SourceLocation{"<estimates>", line_no, 0, "phase"}, "unknown phase '" + s + "'");
}

}  // namespace

std::string estimateCsvHeader() {
  std::string h = "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz";
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) h += fmt::format(",cov_{}_{}", r, c);
  return h + ",phase";
}

std::string estimateHeader(EstimateFormat format) {
  switch (format) {
    case EstimateFormat::kCsv: return estimateCsvHeader();
    case EstimateFormat::kTum: return "# timestamp tx ty tz qx qy qz qw";
    case EstimateFormat::kJson: break;
  }
  return "";
}

std::string formatEstimate(const LocalizerEstimate& e, EstimateFormat format) {
  if (format == EstimateFormat::kTum) {
    const Vec3& p = e.x.w_p_b;
    const Quat& q = e.x.w_q_b;
    return fmt::format("{} {} {} {} {} {} {} {}", e.t_s, p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
  }
  const bool json = format == EstimateFormat::kJson;
  const Vec3& p = e.x.w_p_b;
  const Vec3& v = e.x.w_v_b;
  const Quat& q = e.x.w_q_b;
  std::string out;
  out.reserve(1024);
  const auto list = [&](const char* key, std::initializer_list<double> values) {
    if (json) out += fmt::format(",\"{}\":[", key);
    bool first = true;
    for (double x : values) {
      if (json && !first) out += ',';
      if (!json) out += ',';
      appendNumber(out, x, format);
      first = false;
    }
    if (json) out += ']';
  };
  out += json ? "{\"t\":" : "";
  appendNumber(out, e.t_s, format);
  list("p", {p.x(), p.y(), p.z()});
  list("q", {q.w(), q.x(), q.y(), q.z()});
  list("v", {v.x(), v.y(), v.z()});
  if (json) out += ",\"cov\":[";
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      if (!json || r + c > 0) out += ',';
      appendNumber(out, e.cov_pose(r, c), format);
    }
  out += json ? "],\"phase\":\"" + toString(e.phase) + "\"}" : "," + toString(e.phase);
  return out;
}

LocalizerEstimate parseEstimate(const std::string& line, EstimateFormat format, std::size_t line_no) {
  LocalizerEstimate e;
  const auto bad = [&](const std::string& what) {
    return InputError(SourceLocation{"<estimates>", line_no, 0, ""}, what);
  };
  std::vector<double> v;  // t, p, q(w,x,y,z), v, cov
  std::string phase;
  if (format == EstimateFormat::kTum) {  // t px py pz qx qy qz qw
    std::size_t start = 0;
    while (start < line.size()) {
      while (start < line.size() && line[start] == ' ') ++start;
      if (start >= line.size()) break;
      std::size_t end = line.find(' ', start);
      if (end == std::string::npos) end = line.size();
      double x = 0.0;
      const auto [ptr, ec] = std::from_chars(line.data() + start, line.data() + end, x);
      if (ec != std::errc() || ptr != line.data() + end) throw bad("'" + line.substr(start, end - start) + "' is not a number");
      v.push_back(x);
      start = end;
    }
    if (v.size() != 8) throw bad(fmt::format("{} numbers, expected 8 (t px py pz qx qy qz qw)", v.size()));
    e.t_s = v[0];
    e.x.w_p_b = Vec3(v[1], v[2], v[3]);
    e.x.w_q_b = Quat(v[7], v[4], v[5], v[6]);
    e.x.w_v_b.setZero();
    e.cov_pose.setConstant(NAN);
    e.sigma_p_m.setConstant(NAN);
    e.phase = FlightPhase::kTracking;
    return e;
  }
  if (format == EstimateFormat::kJson) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object()) throw bad("not a JSON object");
    try {
      v.push_back(j.at("t").get<double>());
      for (const char* key : {"p", "q", "v", "cov"})
        for (const auto& x : j.at(key)) v.push_back(x.is_null() ? NAN : x.get<double>());
      phase = j.at("phase").get<std::string>();
    } catch (const nlohmann::json::exception& ex) {
      throw bad(ex.what());
    }
  } else {
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::string cell = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (comma == std::string::npos) {
        phase = cell;
        break;
      }
      double x = 0.0;
      const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), x);
      if (ec != std::errc() || ptr != cell.data() + cell.size()) throw bad("'" + cell + "' is not a number");
      v.push_back(x);
      start = comma + 1;
    }
  }
  if (v.size() != 1 + 3 + 4 + 3 + 36) throw bad(fmt::format("{} numbers, expected 47", v.size()));
  e.t_s = v[0];
  e.x.w_p_b = Vec3(v[1], v[2], v[3]);
  e.x.w_q_b = Quat(v[4], v[5], v[6], v[7]);
  e.x.w_v_b = Vec3(v[8], v[9], v[10]);
  for (int k = 0; k < 36; ++k) e.cov_pose(k / 6, k % 6) = v[11 + k];
  e.sigma_p_m = e.cov_pose.diagonal().head<3>().cwiseSqrt();
  e.phase = phaseFromString(phase, line_no);
  return e;
}

}  // namespace uwb
