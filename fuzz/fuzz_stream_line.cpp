/** @file fuzz_stream_line.cpp
 *  @brief libFuzzer harness of the live stream's input: the input's lines through the sensor-event line protocol
 *         (parseEventLine, then checkEventAnchors against an 8-anchor survey), each accepted event written back with
 *         formatEventLine's shortest text and read again (it must give the same event, bit for bit), then folded
 *         into an EstimateStream (the clock guard and the online estimator) as `uwbtdoa stream` does. A rejected line
 *         is skipped, as `stream` skips it without --strict.
 */
#include <cstring>
#include <stdexcept>
#include <string>

#include "FuzzInput.h"
#include "uwb/stream/EstimateStream.h"
#include "uwb/stream/LineProtocol.h"

namespace {

uwb::AnchorTable fuzzAnchors() {
  uwb::AnchorTable t;
  const double xy[8][3] = {{-3, -4, 0.2}, {-3, 4, 3}, {4, 4, 0.2}, {4, -4, 3}, {-3, -4, 3}, {-3, 4, 0.2}, {4, 4, 3}, {4, -4, 0.2}};
  for (int i = 0; i < 8; ++i) t.set(i, uwb::Vec3(xy[i][0], xy[i][1], xy[i][2]), 0.0);
  return t;
}

bool sameEvent(const uwb::StreamEvent& a, const uwb::StreamEvent& b) {
  if (a.kind != b.kind || std::memcmp(&a.t_s, &b.t_s, sizeof(double)) != 0) return false;
  switch (a.kind) {
    case uwb::StreamEvent::Kind::kImu: return a.imu.b_acc_mps2 == b.imu.b_acc_mps2 && a.imu.b_gyro_radps == b.imu.b_gyro_radps;
    case uwb::StreamEvent::Kind::kTdoa:
      return a.tdoa.id_a == b.tdoa.id_a && a.tdoa.id_b == b.tdoa.id_b && a.tdoa.tdoa_m == b.tdoa.tdoa_m;
    case uwb::StreamEvent::Kind::kTof: return a.tof.range_m == b.tof.range_m;
    case uwb::StreamEvent::Kind::kNone: return true;
  }
  return false;
}

std::string lineOf(const uwb::StreamEvent& ev) {
  switch (ev.kind) {
    case uwb::StreamEvent::Kind::kImu: return uwb::formatImuLine(ev.t_s, ev.imu);
    case uwb::StreamEvent::Kind::kTdoa: return uwb::formatTdoaLine(ev.tdoa);
    case uwb::StreamEvent::Kind::kTof: return uwb::formatTofLine(ev.tof);
    case uwb::StreamEvent::Kind::kNone: return "";
  }
  return "";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  static const AnchorTable anchors = fuzzAnchors();
  const std::string_view text = fuzz::asText(data, size);
  const std::string source = "<fuzz>";
  EstimateStream stream(EkfParams{}, anchors, 0.0, {}, StreamClockParams{5.0, 2.0, 3});
  std::size_t line_no = 0;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t nl = text.find('\n', start);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    const std::string_view line = text.substr(start, end - start);
    ++line_no;
    start = end + 1;
    StreamEvent ev;
    try {
      ev = parseEventLine(line, line_no, source);
      checkEventAnchors(ev, anchors, line_no, source);
    } catch (const InputError&) {
      continue;  // what `stream` skips and counts
    }
    if (ev.kind != StreamEvent::Kind::kNone && !sameEvent(parseEventLine(lineOf(ev), line_no, source), ev))
      throw std::logic_error("an event's shortest text does not read back to the same event");
    stream.add(ev);  // the estimator may refuse nothing here: every exception escapes as a finding
    if (nl == std::string_view::npos) break;
  }
  stream.finish();
  return 0;
}
