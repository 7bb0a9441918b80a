/** @file UsdImport.cpp
 *  @brief Event log ↔ flight (the mapping table is in io/UsdImport.h and docs/io.md §6).
 */
#include "uwb/io/UsdImport.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include "CsvDetail.h"
#include "uwb/core/Error.h"
#include "uwb/core/Strings.h"
#include "uwb/core/Types.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {

namespace {

constexpr double kMicro = 1e6;        // µs per s
constexpr double kMmPerM = 1000.0;    // estTOF range.zrange is in mm

/// UTIL's event types and fields, one entry per way a stream can be recorded (tried in this order).
struct Recording {
  Stream stream;
  const char* event;
  std::vector<const char*> fields;
};

const std::vector<Recording>& recordings() {
  static const std::vector<Recording> kAll{
      {Stream::kTdoa, "estTDOA", {"idA", "idB", "distanceDiff"}},
      {Stream::kTwr, "estDistance", {"id", "distance"}},
      {Stream::kAcc, "estAcceleration", {"acc.x", "acc.y", "acc.z"}},
      {Stream::kGyro, "estGyroscope", {"gyro.x", "gyro.y", "gyro.z"}},
      {Stream::kTof, "estTOF", {"range.zrange"}},
      {Stream::kTof, "estTOF", {"distance"}},
      {Stream::kFlow, "estFlow", {"motion.deltaX", "motion.deltaY"}},
      {Stream::kBaro, "estBarometer", {"baro.asl"}},
      {Stream::kPose, "estPose", {"locSrv.x", "locSrv.y", "locSrv.z", "locSrv.qx", "locSrv.qy", "locSrv.qz", "locSrv.qw"}},
      {Stream::kPose, "estPose", {"x", "y", "z", "quat"}},
      {Stream::kPose, "estPose", {"locSrv.x", "locSrv.y", "locSrv.z"}},
      {Stream::kPose, "estPosition", {"x", "y", "z"}},
      {Stream::kPose, "estPosition", {"locSrv.x", "locSrv.y", "locSrv.z"}},
  };
  return kAll;
}

std::string joined(const std::vector<const char*>& fields) {
  std::string out;
  for (const char* f : fields) appendToList(&out, f);
  return out;
}

/// The firmware's 32-bit "smallest three" quaternion (quatcompress.h): bits 31–30 index the largest component,
/// then three 10-bit groups (from the low bits: the highest remaining index first), each a sign bit and a 9-bit
/// magnitude in units of (1/√2)/511; the largest component is √(1 − Σ others²). Components in (x, y, z, w) order.
Quat decompressQuaternion(std::uint32_t comp) {
  constexpr unsigned kMask = (1u << 9) - 1;
  const double small_max = std::sqrt(0.5);
  const unsigned largest = comp >> 30;
  double q[4] = {0, 0, 0, 0};
  double sum_squares = 0.0;
  for (int i = 3; i >= 0; --i) {
    if (static_cast<unsigned>(i) == largest) continue;
    const unsigned mag = comp & kMask;
    const bool negative = ((comp >> 9) & 1u) != 0;
    comp >>= 10;
    q[i] = small_max * static_cast<double>(mag) / kMask * (negative ? -1.0 : 1.0);
    sum_squares += q[i] * q[i];
  }
  q[largest] = std::sqrt(std::max(0.0, 1.0 - sum_squares));
  return Quat(q[3], q[0], q[1], q[2]);  // Eigen order: w, x, y, z
}

class Converter {
 public:
  Converter(const UsdLog& log, UsdImportReport& report) : log_(log), report_(report), used_(log.types.size(), false) {}

  Flight run() {
    findStartTime();
    for (const Recording& r : recordings()) {
      if (done_[static_cast<int>(r.stream)]) continue;
      const int type = log_.typeIndex(r.event);
      if (type < 0) continue;
      std::vector<std::size_t> fields;
      for (const char* f : r.fields) {
        const int i = log_.types[static_cast<std::size_t>(type)].fieldIndex(f);
        if (i < 0) break;
        fields.push_back(static_cast<std::size_t>(i));
      }
      if (fields.size() != r.fields.size()) continue;
      convert(r, static_cast<std::size_t>(type), fields);
      used_[static_cast<std::size_t>(type)] = true;
      done_[static_cast<int>(r.stream)] = true;
    }
    noteLeftOut();
    if (flight_.tdoa.empty() && flight_.twr.empty() && flight_.acc.empty() && flight_.gyro.empty() &&
        flight_.tof.empty() && flight_.flow.empty() && flight_.baro.empty() && flight_.pose.empty()) {
      throw InputError(fmt::format("{}: no event of the flight layout carries data (known: estTDOA, estDistance, "
                                   "estAcceleration, estGyroscope, estTOF, estFlow, estBarometer, estPose, "
                                   "estPosition; see docs/io.md §6)",
                                   log_.source));
    }
    setColumns();
    flight_.source = log_.source;
    std::sort(report_.sources.begin(), report_.sources.end(), [](const auto& a, const auto& b) {
      return std::find(allStreams().begin(), allStreams().end(), a.stream) <
             std::find(allStreams().begin(), allStreams().end(), b.stream);
    });
    return std::move(flight_);
  }

 private:
  void findStartTime() {
    bool any = false;
    for (const UsdEventSeries& s : log_.events) {
      if (s.size() == 0) continue;
      t0_us_ = any ? std::min(t0_us_, s.t_us.front()) : s.t_us.front();
      any = true;
    }
    report_.t0_us = static_cast<double>(t0_us_);
  }

  double time(const UsdEventSeries& s, std::size_t i) const {
    return static_cast<double>(s.t_us[i] - t0_us_) / kMicro;
  }

  double finite(std::size_t type, std::size_t event, std::size_t field) const {
    const double v = log_.value(type, event, field);
    if (!std::isfinite(v)) {
      throw InputError(log_.where(type, event, static_cast<int>(field)) + ": NaN or Inf is not allowed");
    }
    return v;
  }

  int anchorId(std::size_t type, std::size_t event, std::size_t field) const {
    const double v = finite(type, event, field);
    if (v != std::floor(v) || v < 0 || v > kMaxAnchorId) {
      throw InputError(fmt::format("{}: anchor id must be an integer in [0, {}]: {}",
                                   log_.where(type, event, static_cast<int>(field)), kMaxAnchorId, v));
    }
    return static_cast<int>(v);
  }

  void convert(const Recording& r, std::size_t type, const std::vector<std::size_t>& f) {
    const UsdEventSeries& s = log_.events[type];
    const std::size_t n = s.size();
    const auto v = [&](std::size_t i, std::size_t k) { return finite(type, i, f[k]); };
    const auto vec = [&](std::size_t i, double scale) { return Vec3(v(i, 0) * scale, v(i, 1) * scale, v(i, 2) * scale); };
    switch (r.stream) {
      case Stream::kTdoa:
        flight_.tdoa.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
          flight_.tdoa.push_back({time(s, i), anchorId(type, i, f[0]), anchorId(type, i, f[1]), v(i, 2)});
        }
        break;
      case Stream::kTwr:
        flight_.twr.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.twr.push_back({time(s, i), anchorId(type, i, f[0]), v(i, 1)});
        break;
      case Stream::kAcc:  // g → m/s², the CSV reader's conversion
        flight_.acc.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.acc.push_back({time(s, i), vec(i, kGravity_mps2)});
        break;
      case Stream::kGyro:  // deg/s → rad/s, the CSV reader's conversion
        flight_.gyro.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.gyro.push_back({time(s, i), vec(i, kDegToRad)});
        break;
      case Stream::kTof: {
        const bool millimetres = std::string_view(r.fields[0]) == "range.zrange";
        flight_.tof.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.tof.push_back({time(s, i), millimetres ? v(i, 0) / kMmPerM : v(i, 0)});
        break;
      }
      case Stream::kFlow:
        flight_.flow.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.flow.push_back({time(s, i), v(i, 0), v(i, 1)});
        break;
      case Stream::kBaro:
        flight_.baro.reserve(n);
        for (std::size_t i = 0; i < n; ++i) flight_.baro.push_back({time(s, i), v(i, 0)});
        break;
      case Stream::kPose: convertPose(r, type, f); break;
    }
    report_.sources.push_back({r.stream, r.event, joined(r.fields), n});
  }

  void convertPose(const Recording& r, std::size_t type, const std::vector<std::size_t>& f) {
    const UsdEventSeries& s = log_.events[type];
    flight_.pose.reserve(s.size());
    flight_.pose_has_orientation = f.size() > 3;
    for (std::size_t i = 0; i < s.size(); ++i) {
      PoseSample p;
      p.t_s = time(s, i);
      p.w_p_b = Vec3(finite(type, i, f[0]), finite(type, i, f[1]), finite(type, i, f[2]));
      if (f.size() > 3) {  // the file check of the CSV reader, so that the flight CSV reads back
        const Quat q = f.size() == 7 ? Quat(finite(type, i, f[6]), finite(type, i, f[3]), finite(type, i, f[4]),
                                            finite(type, i, f[5]))
                                     : decompressQuaternion(static_cast<std::uint32_t>(log_.value(type, i, f[3])));
        double norm = 0.0;
        if (!isFileQuaternionNormOk(q.x(), q.y(), q.z(), q.w(), norm)) {
          throw InputError(fmt::format("{}: pose quaternion is far from unit norm: |q| = {:.6g} (tolerance {})",
                                       log_.where(type, i, static_cast<int>(f[3])), norm, kMaxQuaternionNormError));
        }
        p.w_q_b = q;
      }
      flight_.pose.push_back(p);
    }
    if (!flight_.pose_has_orientation) report_.notes.push_back(fmt::format("pose from {}: position only", r.event));
  }

  void noteLeftOut() {
    for (std::size_t k = 0; k < log_.types.size(); ++k) {
      if (used_[k]) continue;
      const UsdEventType& t = log_.types[k];
      const std::size_t n = log_.events[k].size();
      std::string expected;
      for (const Recording& r : recordings()) {
        if (t.name == r.event) expected += fmt::format("{}{{{}}}", expected.empty() ? "" : " or ", joined(r.fields));
      }
      if (!expected.empty() && !done_[static_cast<int>(streamOf(t.name))]) {
        report_.notes.push_back(fmt::format("{} ({} events) lacks the fields of the {} stream: expected {}", t.name, n,
                                            streamName(streamOf(t.name)), expected));
      } else if (n > 0) {
        report_.notes.push_back(fmt::format("{} ({} events) is not part of the flight layout: ignored", t.name, n));
      }
    }
  }

  static Stream streamOf(const std::string& event) {
    for (const Recording& r : recordings()) {
      if (event == r.event) return r.stream;
    }
    return Stream::kTdoa;
  }

  void setColumns() {
    for (Stream s : allStreams()) {
      if (!flight_.has(s)) continue;
      for (const std::string& c : streamColumns(s)) {
        if (s == Stream::kPose && !flight_.pose_has_orientation && c.rfind("pose_q", 0) == 0) continue;
        flight_.columns.push_back(c);
      }
    }
  }

  const UsdLog& log_;
  UsdImportReport& report_;
  std::vector<bool> used_;
  bool done_[8] = {false, false, false, false, false, false, false, false};
  std::uint64_t t0_us_ = 0;
  Flight flight_;
};

}  // namespace

std::vector<UsdRecording> usdRecordings() {
  std::vector<UsdRecording> out;
  for (const Recording& r : recordings()) out.push_back({r.stream, r.event, std::vector<std::string>(r.fields.begin(), r.fields.end())});
  return out;
}

Flight flightFromUsdLog(const UsdLog& log, UsdImportReport* report) {
  UsdImportReport local;
  UsdImportReport& rep = report != nullptr ? *report : local;
  return Converter(log, rep).run();
}

Flight importUsdLog(const std::string& path, const UsdReadOptions& options, UsdImportReport* report) {
  UsdReadReport read_report;
  const UsdLog log = readUsdLog(path, options, &read_report);
  UsdImportReport local;
  UsdImportReport& rep = report != nullptr ? *report : local;
  rep = UsdImportReport{};
  rep.notes = read_report.notes;
  return flightFromUsdLog(log, &rep);
}

namespace {

/// (stream, event type index) of the types declared in a log, in UTIL column order.
using DeclaredTypes = std::vector<std::pair<Stream, std::size_t>>;

/// Declares one event type per stream (ids 1, 2, … in UTIL column order, also for the streams left out); returns
/// those of the streams the flight has.
DeclaredTypes declareEventTypes(const Flight& flight, UsdLog& log) {
  constexpr auto F = UsdType::kFloat;
  DeclaredTypes declared;
  std::uint16_t next_id = 1;
  const auto declare = [&](Stream s, const char* name, std::vector<std::pair<std::string, UsdType>> fields) {
    if (flight.has(s)) declared.emplace_back(s, log.addType(next_id, name, fields));
    ++next_id;
  };
  declare(Stream::kTwr, "estDistance", {{"id", UsdType::kUint8}, {"distance", F}});
  declare(Stream::kTdoa, "estTDOA", {{"idA", UsdType::kUint8}, {"idB", UsdType::kUint8}, {"distanceDiff", F}});
  declare(Stream::kAcc, "estAcceleration", {{"acc.x", F}, {"acc.y", F}, {"acc.z", F}});
  declare(Stream::kGyro, "estGyroscope", {{"gyro.x", F}, {"gyro.y", F}, {"gyro.z", F}});
  declare(Stream::kTof, "estTOF", {{"range.zrange", UsdType::kUint16}});
  declare(Stream::kFlow, "estFlow", {{"motion.deltaX", UsdType::kInt16}, {"motion.deltaY", UsdType::kInt16}});
  declare(Stream::kBaro, "estBarometer", {{"baro.asl", F}});
  if (flight.pose_has_orientation) {
    declare(Stream::kPose, "estPose", {{"locSrv.x", F}, {"locSrv.y", F}, {"locSrv.z", F}, {"locSrv.qx", F},
                                       {"locSrv.qy", F}, {"locSrv.qz", F}, {"locSrv.qw", F}});
  } else {
    declare(Stream::kPose, "estPose", {{"locSrv.x", F}, {"locSrv.y", F}, {"locSrv.z", F}});
  }
  return declared;
}

double sampleTime(const Flight& flight, Stream s, std::size_t i) {
  switch (s) {
    case Stream::kTdoa: return flight.tdoa[i].t_s;
    case Stream::kTwr: return flight.twr[i].t_s;
    case Stream::kAcc: return flight.acc[i].t_s;
    case Stream::kGyro: return flight.gyro[i].t_s;
    case Stream::kTof: return flight.tof[i].t_s;
    case Stream::kFlow: return flight.flow[i].t_s;
    case Stream::kBaro: return flight.baro[i].t_s;
    case Stream::kPose: return flight.pose[i].t_s;
  }
  return 0.0;
}

/// Events of all streams by time (ties: UTIL column order, then sample order): (t_us, declared index, sample).
std::vector<std::tuple<std::uint64_t, std::size_t, std::size_t>> eventOrder(const Flight& flight,
                                                                            const DeclaredTypes& declared) {
  const auto micros = [](double t) {
    if (!(t >= 0.0) || t * kMicro > 9.0e15) throw std::invalid_argument(fmt::format("time {} s cannot be a log timestamp", t));
    return static_cast<std::uint64_t>(std::llround(t * kMicro));
  };
  std::vector<std::tuple<std::uint64_t, std::size_t, std::size_t>> order;
  for (std::size_t d = 0; d < declared.size(); ++d) {
    const Stream s = declared[d].first;
    for (std::size_t i = 0; i < io_detail::streamSize(flight, s); ++i) order.emplace_back(micros(sampleTime(flight, s, i)), d, i);
  }
  std::sort(order.begin(), order.end());
  return order;
}

/// Sample i of stream s as an event of the given type, in the log's units (g, deg/s, mm).
void addSampleEvent(UsdLog& log, const Flight& flight, Stream s, std::size_t type, std::uint64_t t_us, std::size_t i) {
  const auto g = [](double x) { return io_detail::unscaleExactly(x, kGravity_mps2); };
  const auto deg = [](double x) { return io_detail::unscaleExactly(x, kDegToRad); };
  switch (s) {
    case Stream::kTdoa: {
      const auto& m = flight.tdoa[i];
      log.addEvent(type, t_us, {double(m.id_a), double(m.id_b), m.tdoa_m});
      break;
    }
    case Stream::kTwr: log.addEvent(type, t_us, {double(flight.twr[i].anchor_id), flight.twr[i].range_m}); break;
    case Stream::kAcc: {
      const Vec3& a = flight.acc[i].b_value;
      log.addEvent(type, t_us, {g(a.x()), g(a.y()), g(a.z())});
      break;
    }
    case Stream::kGyro: {
      const Vec3& w = flight.gyro[i].b_value;
      log.addEvent(type, t_us, {deg(w.x()), deg(w.y()), deg(w.z())});
      break;
    }
    case Stream::kTof: log.addEvent(type, t_us, {std::nearbyint(flight.tof[i].value * kMmPerM)}); break;
    case Stream::kFlow: log.addEvent(type, t_us, {flight.flow[i].delta_x, flight.flow[i].delta_y}); break;
    case Stream::kBaro: log.addEvent(type, t_us, {flight.baro[i].value}); break;
    case Stream::kPose: {
      const PoseSample& p = flight.pose[i];
      if (flight.pose_has_orientation) {
        log.addEvent(type, t_us, {p.w_p_b.x(), p.w_p_b.y(), p.w_p_b.z(), p.w_q_b.x(), p.w_q_b.y(), p.w_q_b.z(), p.w_q_b.w()});
      } else {
        log.addEvent(type, t_us, {p.w_p_b.x(), p.w_p_b.y(), p.w_p_b.z()});
      }
      break;
    }
  }
}

}  // namespace

UsdLog usdLogFromFlight(const Flight& flight) {
  UsdLog log;
  log.version = 2;
  log.source = flight.source;
  const DeclaredTypes declared = declareEventTypes(flight, log);
  for (const auto& [t_us, d, i] : eventOrder(flight, declared)) {
    addSampleEvent(log, flight, declared[d].first, declared[d].second, t_us, i);
  }
  return log;
}

}  // namespace uwb
