/** @file ImuSignature.cpp
 *  @brief Another drone's IMU signature on a flight (docs/math/simulation.md S24).
 */
#include "uwb/sim/ImuSignature.h"

#include "uwb/io/PoseTrack.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

namespace uwb::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
constexpr double kG = 9.80665;
/// Still MEMS IMU with the motors off (util-pilot, first second of every flight): ≈ 0.003 g and 0.004 rad/s RMS of
/// the norm (S24).
constexpr double kMotorsOffAcc_mps2 = 0.003 * kG;
constexpr double kMotorsOffGyro_radps = 0.004;
/// Rotor tones (S24): three per axis in this band [Hz], and broadband noise of this fraction of the tones' RMS.
constexpr double kToneMin_hz = 150.0, kToneMax_hz = 240.0;
constexpr int kTonesPerAxis = 3;
constexpr double kBroadbandFraction = 0.25;

/// The floor level: the 2nd percentile of the pose heights.
double floorLevel(const std::vector<PoseSample>& pose) {
  if (pose.empty()) throw std::invalid_argument("truthFloorLevel: no pose samples");
  std::vector<double> z;
  z.reserve(pose.size());
  for (const PoseSample& p : pose) z.push_back(p.w_p_b.z());
  const auto k = static_cast<std::ptrdiff_t>(0.02 * static_cast<double>(z.size() - 1));
  std::nth_element(z.begin(), z.begin() + k, z.end());
  return z[static_cast<std::size_t>(k)];
}

}  // namespace

double truthHeightAt(const std::vector<PoseSample>& pose, double t_s) {
  const double t = std::clamp(t_s, pose.front().t_s, pose.back().t_s);
  const std::optional<PoseSample> p = interpolatePose(pose, t, std::numeric_limits<double>::infinity(), false);
  return p ? p->w_p_b.z() : pose.front().w_p_b.z();
}

double truthFloorLevel(const std::vector<PoseSample>& pose) { return floorLevel(pose); }

namespace {

/// Centred moving mean over n samples (prefix sums; the ends use the samples there are).
std::vector<Vec3> movingMean(const std::vector<ImuSample>& s, std::size_t n) {
  std::vector<Vec3> prefix(s.size() + 1, Vec3::Zero());
  for (std::size_t i = 0; i < s.size(); ++i) prefix[i + 1] = prefix[i] + s[i].b_value;
  std::vector<Vec3> out(s.size());
  const std::size_t half = n / 2;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t lo = i >= half ? i - half : 0;
    const std::size_t hi = std::min(s.size(), lo + std::max<std::size_t>(n, 1));
    out[i] = (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo);
  }
  return out;
}

/// Rotor vibration (S24): per axis three tones in [150, 240] Hz plus broadband noise, RMS of the norm `rms`.
struct Vibration {
  std::array<double, 3 * kTonesPerAxis> f_hz{}, phase{};
  double tone_amp = 0.0, noise_std = 0.0;
  Vibration(double rms, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> f(kToneMin_hz, kToneMax_hz), ph(0.0, 2.0 * kPi);
    for (int k = 0; k < 3 * kTonesPerAxis; ++k) {
      f_hz[k] = f(rng);
      phase[k] = ph(rng);
    }
    // per axis: variance rms²/3, split between the tones and kBroadbandFraction² of it as noise
    const double axis_rms = rms / std::sqrt(3.0) / std::sqrt(1.0 + kBroadbandFraction * kBroadbandFraction);
    tone_amp = axis_rms * std::sqrt(2.0 / kTonesPerAxis);
    noise_std = axis_rms * kBroadbandFraction;
  }
  Vec3 at(double t, std::mt19937_64& rng) const {
    std::normal_distribution<double> n(0.0, 1.0);
    Vec3 v;
    for (int ax = 0; ax < 3; ++ax) {
      double s = 0.0;
      for (int k = 0; k < kTonesPerAxis; ++k)
        s += std::sin(2.0 * kPi * f_hz[ax * kTonesPerAxis + k] * t + phase[ax * kTonesPerAxis + k]);
      v[ax] = tone_amp * s + noise_std * n(rng);
    }
    return v;
  }
};

void applyToStream(std::vector<ImuSample>& s, const ImuSignature& sig, bool gyro, const std::vector<PoseSample>& pose,
                   double floor_z, std::mt19937_64& rng) {
  if (s.size() < 2) return;
  const double flight_rms = gyro ? sig.flight_gyro_vib_rms_radps : sig.flight_acc_vib_rms_mps2;
  const double idle_rms = gyro ? sig.floor_gyro_vib_rms_radps : sig.floor_acc_vib_rms_mps2;
  const double quiet = gyro ? kMotorsOffGyro_radps : kMotorsOffAcc_mps2;
  const bool touch_floor = sig.floor != FloorImu::kUnchanged;
  if (flight_rms > 0.0 || sig.replace_flight || touch_floor) {
    const double dt = (s.back().t_s - s.front().t_s) / static_cast<double>(s.size() - 1);
    const auto n = static_cast<std::size_t>(std::max(1.0, std::round(sig.smooth_s / std::max(dt, 1e-6))));
    const std::vector<Vec3> low = movingMean(s, n);
    const Vibration flight_vib(flight_rms, rng), idle_vib(idle_rms, rng);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double t = s[i].t_s;
      const bool air = truthHeightAt(pose, t) > floor_z + sig.air_height_m;
      if (air) {
        if (sig.replace_flight) s[i].b_value = low[i];
        if (flight_rms > 0.0) s[i].b_value += flight_vib.at(t, rng);
      } else if (sig.floor == FloorImu::kMotorsOff) {
        s[i].b_value = low[i] + (quiet / std::sqrt(3.0)) * Vec3(unit(rng), unit(rng), unit(rng));
      } else if (sig.floor == FloorImu::kIdle) {
        s[i].b_value = low[i] + idle_vib.at(t, rng);
      }
    }
  }
  const Vec3& bias = gyro ? sig.gyro_bias_radps : sig.acc_bias_mps2;
  for (ImuSample& x : s) x.b_value += bias;
}

/// Block means of `factor` samples, stamped at the block's last sample (an IMU's own low-pass and decimation).
void decimate(std::vector<ImuSample>& s, std::size_t factor) {
  if (factor <= 1) return;
  std::vector<ImuSample> out;
  out.reserve(s.size() / factor + 1);
  for (std::size_t i = 0; i + factor <= s.size(); i += factor) {
    Vec3 sum = Vec3::Zero();
    for (std::size_t k = 0; k < factor; ++k) sum += s[i + k].b_value;
    out.push_back({s[i + factor - 1].t_s, sum / static_cast<double>(factor)});
  }
  s = std::move(out);
}

}  // namespace

std::string toString(FloorImu floor) {
  switch (floor) {
    case FloorImu::kUnchanged: return "as logged";
    case FloorImu::kMotorsOff: return "motors off";
    case FloorImu::kIdle: return "idle";
  }
  return "unknown";
}

void ImuSignature::validate() const {
  const auto bad = [](const char* field) {
    throw std::invalid_argument(std::string("ImuSignature: ") + field + " must be finite and >= 0");
  };
  const auto ok = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!ok(flight_gyro_vib_rms_radps)) bad("flight_gyro_vib_rms_radps");
  if (!ok(flight_acc_vib_rms_mps2)) bad("flight_acc_vib_rms_mps2");
  if (!ok(floor_gyro_vib_rms_radps)) bad("floor_gyro_vib_rms_radps");
  if (!ok(floor_acc_vib_rms_mps2)) bad("floor_acc_vib_rms_mps2");
  if (!ok(rate_hz)) bad("rate_hz");
  if (!ok(lag_s)) bad("lag_s");
  if (!(smooth_s > 0.0 && std::isfinite(smooth_s))) bad("smooth_s (> 0)");
  if (!ok(air_height_m)) bad("air_height_m");
  if (!gyro_bias_radps.allFinite()) bad("gyro_bias_radps");
  if (!acc_bias_mps2.allFinite()) bad("acc_bias_mps2");
}

std::string ImuSignature::label() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "gyro %.0f°/s, acc %.3g g, floor %s", flight_gyro_vib_rms_radps * kDegPerRad,
                flight_acc_vib_rms_mps2 / kG, toString(floor).c_str());
  std::string s = buf;
  if (floor == FloorImu::kIdle) {
    std::snprintf(buf, sizeof buf, " %.0f°/s", floor_gyro_vib_rms_radps * kDegPerRad);
    s += buf;
  }
  if (rate_hz > 0.0) {
    std::snprintf(buf, sizeof buf, ", %.0f Hz", rate_hz);
    s += buf;
  }
  if (gyro_bias_radps.norm() > 0.0) {
    std::snprintf(buf, sizeof buf, ", gyro bias %.1f°/s", gyro_bias_radps.norm() * kDegPerRad);
    s += buf;
  }
  if (acc_bias_mps2.norm() > 0.0) {
    std::snprintf(buf, sizeof buf, ", acc bias %.2f g", acc_bias_mps2.norm() / kG);
    s += buf;
  }
  if (lag_s > 0.0) {
    std::snprintf(buf, sizeof buf, ", lag %.0f ms", lag_s * 1e3);
    s += buf;
  }
  return s;
}

void applyImuSignature(Flight& flight, const ImuSignature& sig, std::uint64_t seed) {
  sig.validate();
  if (flight.pose.size() < 2) throw std::invalid_argument("applyImuSignature: the flight has no ground-truth pose");
  if (flight.acc.size() < 2 || flight.gyro.size() < 2) throw std::invalid_argument("applyImuSignature: no IMU");
  const double floor_z = floorLevel(flight.pose);
  std::mt19937_64 rng(seed);
  applyToStream(flight.gyro, sig, true, flight.pose, floor_z, rng);
  applyToStream(flight.acc, sig, false, flight.pose, floor_z, rng);
  if (sig.rate_hz > 0.0) {
    const double dt = (flight.gyro.back().t_s - flight.gyro.front().t_s) / static_cast<double>(flight.gyro.size() - 1);
    const auto factor = static_cast<std::size_t>(std::max(1.0, std::round(1.0 / (sig.rate_hz * dt))));
    decimate(flight.gyro, factor);
    decimate(flight.acc, factor);
  }
  for (ImuSample& x : flight.gyro) x.t_s += sig.lag_s;
  for (ImuSample& x : flight.acc) x.t_s += sig.lag_s;
}

}  // namespace uwb::sim
