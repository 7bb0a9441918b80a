/** @file IoTestHelpers.h
 *  @brief Helpers of the io tests: bitwise flight comparison, real-data locations.
 */
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "support/TestSupport.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/UtilCsv.h"

namespace uwb::test {

inline Quat yaw(double rad) { return Quat(Eigen::AngleAxisd(rad, Vec3::UnitZ())); }
inline Quat roll(double rad) { return Quat(Eigen::AngleAxisd(rad, Vec3::UnitX())); }

/// A circle at 1.5 m height, radius 1.5 m, ω rad/s, sampled at `rate_hz`, yawing slowly.
inline std::vector<PoseSample> circle(double rate_hz, double duration_s, double omega = 1.0) {
  std::vector<PoseSample> out;
  for (int i = 0; i * (1.0 / rate_hz) <= duration_s; ++i) {
    const double t = i / rate_hz;
    out.push_back({t, Vec3(1.5 * std::cos(omega * t), 1.5 * std::sin(omega * t), 1.5), yaw(0.1 * t)});
  }
  return out;
}

/// Eight anchors in the corners of an 8 m × 8 m room, low and high.
inline AnchorSurvey cornerSurvey() {
  AnchorSurvey s;
  const double z[8] = {0.2, 2.9, 0.2, 3.2, 3.0, 0.2, 3.1, 0.2};
  const double xy[8][2] = {{-3, -4}, {-3.2, 3.8}, {3.7, 3.7}, {4.1, -4.3}, {-3, -4.4}, {3.9, -3.8}, {4, 3.9}, {-3.2, 3.3}};
  for (int i = 0; i < 8; ++i) s.anchors.push_back({i, Vec3(xy[i][0], xy[i][1], z[i]), Quat::Identity()});
  return s;
}

/// The `E` that `f()` throws; nullopt, and a failure of the calling test, when it throws nothing or another type.
template <class E, class F>
std::optional<E> caught(F&& f) {
  try {
    f();
    ADD_FAILURE() << "expected " << typeid(E).name() << ", nothing thrown";
  } catch (const E& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected " << typeid(E).name() << ", got " << typeid(e).name() << ": " << e.what();
  }
  return std::nullopt;
}

/// The message of the `E` that `f()` throws (caught); a placeholder that names no file when there is none.
template <class E, class F>
std::string messageOf(F&& f) {
  const std::optional<E> e = caught<E>(std::forward<F>(f));
  return e ? std::string(e->what()) : std::string("(no exception of the expected type)");
}

/// Expects `f()` to throw an `E` whose message contains every part.
template <class E, class F>
void expectThrows(F&& f, const std::vector<std::string>& parts) {
  const std::string message = messageOf<E>(std::forward<F>(f));
  for (const auto& p : parts) EXPECT_THAT(message, ::testing::HasSubstr(p));
}

/// The sample count of every stream of a flight, compared and printed at once.
struct StreamSizes {
  std::size_t tdoa = 0, twr = 0, acc = 0, gyro = 0, tof = 0, flow = 0, baro = 0, pose = 0;
  bool operator==(const StreamSizes&) const = default;
};

inline StreamSizes streamSizes(const Flight& f) {
  return {f.tdoa.size(), f.twr.size(), f.acc.size(), f.gyro.size(), f.tof.size(), f.flow.size(), f.baro.size(),
          f.pose.size()};
}

inline std::ostream& operator<<(std::ostream& os, const StreamSizes& s) {
  return os << "tdoa " << s.tdoa << ", twr " << s.twr << ", acc " << s.acc << ", gyro " << s.gyro << ", tof " << s.tof
            << ", flow " << s.flow << ", baro " << s.baro << ", pose " << s.pose;
}

/// readFlightCsv of `text` written to the file `name` in `dir`.
inline Flight readFlightText(const TempDir& dir, const std::string& name, const std::string& text) {
  return readFlightCsv(dir.write(name, text));
}

inline bool sameBits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
inline bool sameBits(const Vec3& a, const Vec3& b) {
  return sameBits(a.x(), b.x()) && sameBits(a.y(), b.y()) && sameBits(a.z(), b.z());
}
inline bool sameBits(const Quat& a, const Quat& b) {
  return sameBits(a.x(), b.x()) && sameBits(a.y(), b.y()) && sameBits(a.z(), b.z()) && sameBits(a.w(), b.w());
}

/// Every sample of every stream equal bit for bit (and the same columns and pose_has_orientation).
inline ::testing::AssertionResult flightsIdentical(const Flight& a, const Flight& b) {
  if (a.columns != b.columns) return ::testing::AssertionFailure() << "columns differ";
  if (a.pose_has_orientation != b.pose_has_orientation) return ::testing::AssertionFailure() << "orientation flag";
#define UWB_CMP_SIZE(s) \
  if (a.s.size() != b.s.size()) return ::testing::AssertionFailure() << #s " size " << a.s.size() << " vs " << b.s.size();
  UWB_CMP_SIZE(tdoa) UWB_CMP_SIZE(twr) UWB_CMP_SIZE(acc) UWB_CMP_SIZE(gyro) UWB_CMP_SIZE(tof) UWB_CMP_SIZE(flow)
  UWB_CMP_SIZE(baro) UWB_CMP_SIZE(pose)
#undef UWB_CMP_SIZE
  for (std::size_t i = 0; i < a.tdoa.size(); ++i) {
    const auto &x = a.tdoa[i], &y = b.tdoa[i];
    if (!sameBits(x.t_s, y.t_s) || x.id_a != y.id_a || x.id_b != y.id_b || !sameBits(x.tdoa_m, y.tdoa_m))
      return ::testing::AssertionFailure() << "tdoa[" << i << "]";
  }
  for (std::size_t i = 0; i < a.twr.size(); ++i) {
    const auto &x = a.twr[i], &y = b.twr[i];
    if (!sameBits(x.t_s, y.t_s) || x.anchor_id != y.anchor_id || !sameBits(x.range_m, y.range_m))
      return ::testing::AssertionFailure() << "twr[" << i << "]";
  }
  for (std::size_t i = 0; i < a.acc.size(); ++i) {
    if (!sameBits(a.acc[i].t_s, b.acc[i].t_s) || !sameBits(a.acc[i].b_value, b.acc[i].b_value))
      return ::testing::AssertionFailure() << "acc[" << i << "] " << a.acc[i].b_value.transpose() << " vs "
                                           << b.acc[i].b_value.transpose();
  }
  for (std::size_t i = 0; i < a.gyro.size(); ++i) {
    if (!sameBits(a.gyro[i].t_s, b.gyro[i].t_s) || !sameBits(a.gyro[i].b_value, b.gyro[i].b_value))
      return ::testing::AssertionFailure() << "gyro[" << i << "]";
  }
  for (std::size_t i = 0; i < a.tof.size(); ++i) {
    if (!sameBits(a.tof[i].t_s, b.tof[i].t_s) || !sameBits(a.tof[i].value, b.tof[i].value))
      return ::testing::AssertionFailure() << "tof[" << i << "]";
  }
  for (std::size_t i = 0; i < a.baro.size(); ++i) {
    if (!sameBits(a.baro[i].t_s, b.baro[i].t_s) || !sameBits(a.baro[i].value, b.baro[i].value))
      return ::testing::AssertionFailure() << "baro[" << i << "]";
  }
  for (std::size_t i = 0; i < a.flow.size(); ++i) {
    const auto &x = a.flow[i], &y = b.flow[i];
    if (!sameBits(x.t_s, y.t_s) || !sameBits(x.delta_x, y.delta_x) || !sameBits(x.delta_y, y.delta_y))
      return ::testing::AssertionFailure() << "flow[" << i << "]";
  }
  for (std::size_t i = 0; i < a.pose.size(); ++i) {
    const auto &x = a.pose[i], &y = b.pose[i];
    if (!sameBits(x.t_s, y.t_s) || !sameBits(x.w_p_b, y.w_p_b) || !sameBits(x.w_q_b, y.w_q_b))
      return ::testing::AssertionFailure() << "pose[" << i << "]";
  }
  return ::testing::AssertionSuccess();
}

inline std::filesystem::path realDir() { return dataDir() / "real"; }

}  // namespace uwb::test
