/** @file LineProtocol.cpp
 *  @brief Decoding and encoding of the sensor-event line protocol (docs/io.md §5).
 */
#include "uwb/stream/LineProtocol.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fmt/format.h>

#include "uwb/core/Error.h"
#include "uwb/io/AnchorSurvey.h"

namespace uwb {
namespace {

struct Field {
  std::string_view text;
  std::size_t column = 1;  // 1-based column of the field's first character
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

class LineDecoder {
 public:
  LineDecoder(std::string_view line, std::size_t line_no, const std::string& source)
      : line_no_(line_no), source_(source) {
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
      if (n_ < fields_.size()) fields_[n_] = {trim(line.substr(start, end - start)), start + 1};
      ++n_;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
  }
  std::size_t size() const { return n_; }
  std::string_view text(std::size_t i) const { return fields_[i].text; }

  [[noreturn]] void fail(std::size_t i, const char* name, const std::string& what) const {
    const std::size_t column = i < fields_.size() && i < n_ ? fields_[i].column : 0;
    throw InputError(SourceLocation{source_, line_no_, column, name}, what);
  }
  void expectCount(std::size_t n, const char* type, const char* layout) const {
    if (n_ == n) return;
    const std::size_t i = n_ < n ? n_ - 1 : n;  // the first missing (last present) or first extra field
    fail(i, n_ < n ? "missing field" : "extra field",
         fmt::format("a '{}' line has {} fields ({}), this one has {}", type, n, layout, n_));
  }
  double real(std::size_t i, const char* name) const {
    const double v = whole<double>(i, name, "a number");
    if (!std::isfinite(v)) fail(i, name, fmt::format("'{}' is not finite", fields_[i].text));
    return v;
  }
  int integer(std::size_t i, const char* name) const {
    const int v = whole<int>(i, name, "an integer anchor id");
    if (v < 0 || v > kMaxAnchorId)
      fail(i, name, fmt::format("anchor id {} is outside [0, {}] (8-bit Loco Positioning ids)", v, kMaxAnchorId));
    return v;
  }

 private:
  /// Field i read as a whole by std::from_chars; `kind` names what was expected in the message.
  template <class T>
  T whole(std::size_t i, const char* name, const char* kind) const {
    const std::string_view s = fields_[i].text;
    T v{};
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
      fail(i, name, fmt::format("'{}' is not {}", s, kind));
    return v;
  }

  std::array<Field, 9> fields_{};  // the longest line has 8 fields; one more tells "extra field"
  std::size_t n_ = 0;
  std::size_t line_no_;
  const std::string& source_;
};

}  // namespace

StreamEvent parseEventLine(std::string_view line, std::size_t line_no, const std::string& source) {
  StreamEvent ev;
  const std::string_view body = trim(line);
  if (body.empty() || body.front() == '#') return ev;
  const LineDecoder d(line, line_no, source);
  const std::string_view type = d.text(0);
  if (type == "imu") {
    d.expectCount(8, "imu", "imu,t,ax,ay,az,gx,gy,gz");
    ev.kind = StreamEvent::Kind::kImu;
    ev.t_s = d.real(1, "t");
    ev.imu.b_acc_mps2 = Vec3(d.real(2, "ax"), d.real(3, "ay"), d.real(4, "az"));
    ev.imu.b_gyro_radps = Vec3(d.real(5, "gx"), d.real(6, "gy"), d.real(7, "gz"));
  } else if (type == "tdoa") {
    d.expectCount(5, "tdoa", "tdoa,t,id_a,id_b,tdoa_m");
    ev.kind = StreamEvent::Kind::kTdoa;
    ev.t_s = d.real(1, "t");
    ev.tdoa = {ev.t_s, d.integer(2, "id_a"), d.integer(3, "id_b"), d.real(4, "tdoa_m")};
    if (ev.tdoa.id_a == ev.tdoa.id_b)
      d.fail(3, "id_b", fmt::format("id_a and id_b are both {}: a TDoA needs two anchors", ev.tdoa.id_a));
  } else if (type == "tof") {
    d.expectCount(3, "tof", "tof,t,range_m");
    ev.kind = StreamEvent::Kind::kTof;
    ev.t_s = d.real(1, "t");
    ev.tof = {ev.t_s, d.real(2, "range_m")};
  } else {
    d.fail(0, "type", fmt::format("unknown event type '{}' (expected imu, tdoa or tof)", type));
  }
  return ev;
}

void checkEventAnchors(const StreamEvent& ev, const AnchorTable& anchors, std::size_t line_no,
                       const std::string& source) {
  if (ev.kind != StreamEvent::Kind::kTdoa) return;
  for (const auto& [id, name] : {std::pair{ev.tdoa.id_a, "id_a"}, std::pair{ev.tdoa.id_b, "id_b"}})
    if (anchors.find(id) == nullptr)
      throw InputError(SourceLocation{source, line_no, 0, name}, fmt::format("anchor {} is not in the survey", id));
}

std::string formatImuLine(double t_s, const ImuReading& imu) {
  const Vec3& a = imu.b_acc_mps2;
  const Vec3& g = imu.b_gyro_radps;
  return fmt::format("imu,{},{},{},{},{},{},{}", t_s, a.x(), a.y(), a.z(), g.x(), g.y(), g.z());
}

std::string formatTdoaLine(const TdoaMeasurement& z) {
  return fmt::format("tdoa,{},{},{},{}", z.t_s, z.id_a, z.id_b, z.tdoa_m);
}

std::string formatTofLine(const TofObservation& z) { return fmt::format("tof,{},{}", z.t_s, z.range_m); }

std::string formatEventLine(const SensorLog& log, const SensorEvent& ev) {
  switch (ev.kind) {
    case SensorEvent::Kind::kImu: return formatImuLine(log.imu[ev.index].t_s, log.imu[ev.index].imu);
    case SensorEvent::Kind::kTdoa: return formatTdoaLine(log.tdoa[ev.index]);
    case SensorEvent::Kind::kTof: return formatTofLine(log.tof[ev.index]);
  }
  return {};
}

}  // namespace uwb
