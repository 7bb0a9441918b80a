/** @file ImuSignature.cpp
 *  @brief Another drone's IMU signature on a flight (docs/math/simulation.md S24).
 */
#include "uwb/sim/ImuSignature.h"

#include "uwb/core/Smoothstep.h"
#include "uwb/io/PoseTrack.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
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
/// A hand's wobble (docs/math/simulation.md S24b): per axis two sway tones and one tremor tone in these bands [Hz],
/// faded in and out over kHandFade_s at a floor phase's ends, so that the attitude is continuous at take-off [s].
constexpr double kSwayMin_hz = 0.3, kSwayMax_hz = 1.5, kTremorMin_hz = 6.0, kTremorMax_hz = 12.0;
constexpr double kHandFade_s = 0.5;

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

/// The times at which the truth crosses between floor and air (pose sorted by time).
std::vector<double> phaseEdges(const std::vector<PoseSample>& pose, double floor_z, double air_height_m) {
  std::vector<double> edges;
  for (std::size_t i = 1; i < pose.size(); ++i)
    if ((pose[i].w_p_b.z() > floor_z + air_height_m) != (pose[i - 1].w_p_b.z() > floor_z + air_height_m))
      edges.push_back(pose[i].t_s);
  return edges;
}

/// A hand's wobble of the body about its origin (S24b): small angles θ(t) per axis, faded to zero within kHandFade_s of
/// a floor phase's ends. The gyro reads θ̇, the accelerometer f − θ × f (the body turned by θ under a still origin).
struct HandWobble {
  std::array<double, 9> f_hz{}, phase{}, amp{};  ///< per axis: two sway tones and one tremor tone
  std::vector<double> edges;                     ///< floor/air crossings of the truth [s]
  HandWobble(double rms_radps, std::vector<double> phase_edges, std::mt19937_64& rng) : edges(std::move(phase_edges)) {
    std::uniform_real_distribution<double> sway(kSwayMin_hz, kSwayMax_hz), tremor(kTremorMin_hz, kTremorMax_hz),
        ph(0.0, 2.0 * kPi);
    // each tone carries a third of the per-axis rate variance (rms²/3): rate amplitude b = (rms/√3)·√(2/3), θ = b/(2πf)
    const double rate_amp = rms_radps / std::sqrt(3.0) * std::sqrt(2.0 / 3.0);
    for (int k = 0; k < 9; ++k) {
      f_hz[k] = k % 3 == 2 ? tremor(rng) : sway(rng);
      phase[k] = ph(rng);
      amp[k] = rate_amp / (2.0 * kPi * f_hz[k]);
    }
  }
  /// Fade weight: 0 at a floor/air crossing, 1 from kHandFade_s away (the cubic smoothstep, core/Smoothstep.h).
  double weight(double t) const {
    double d = std::numeric_limits<double>::infinity();
    const auto it = std::lower_bound(edges.begin(), edges.end(), t);
    if (it != edges.end()) d = std::min(d, *it - t);
    if (it != edges.begin()) d = std::min(d, t - *std::prev(it));
    return smoothstep3(d / kHandFade_s);
  }
  Vec3 angle(double t) const {
    Vec3 th = Vec3::Zero();
    for (int k = 0; k < 9; ++k) th[k / 3] += amp[k] * std::sin(2.0 * kPi * f_hz[k] * t + phase[k]);
    return weight(t) * th;
  }
  /// θ̇ by a central difference of the faded angle (the fade's own rate included).
  Vec3 rate(double t) const {
    constexpr double h = 1e-4;
    return (angle(t + h) - angle(t - h)) / (2.0 * h);
  }
};

void applyToStream(std::vector<ImuSample>& s, const ImuSignature& sig, bool gyro, const std::vector<PoseSample>& pose,
                   double floor_z, const HandWobble* hand, std::mt19937_64& rng) {
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
      } else if (sig.floor == FloorImu::kHandHeld && hand != nullptr) {
        const Vec3 turn = gyro ? hand->rate(t) : Vec3(-hand->angle(t).cross(low[i]));
        s[i].b_value = low[i] + turn + (quiet / std::sqrt(3.0)) * Vec3(unit(rng), unit(rng), unit(rng));
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

/// Linear interpolation onto a uniform grid at rate_hz from the first stamp to the last (an IMU faster than the log).
void interpolate(std::vector<ImuSample>& s, double rate_hz) {
  std::vector<ImuSample> out;
  const double t0 = s.front().t_s, dt = 1.0 / rate_hz;
  out.reserve(static_cast<std::size_t>((s.back().t_s - t0) * rate_hz) + 2);
  std::size_t j = 0;
  for (std::size_t k = 0;; ++k) {
    const double t = t0 + static_cast<double>(k) * dt;
    if (t > s.back().t_s) break;
    while (j + 2 < s.size() && s[j + 1].t_s <= t) ++j;
    const double span = s[j + 1].t_s - s[j].t_s;
    const double w = span > 0.0 ? std::clamp((t - s[j].t_s) / span, 0.0, 1.0) : 0.0;
    out.push_back({t, (1.0 - w) * s[j].b_value + w * s[j + 1].b_value});
  }
  s = std::move(out);
}

double meanPeriod(const std::vector<ImuSample>& s) {
  return (s.back().t_s - s.front().t_s) / static_cast<double>(s.size() - 1);
}

}  // namespace

std::string toString(FloorImu floor) {
  switch (floor) {
    case FloorImu::kUnchanged: return "as logged";
    case FloorImu::kMotorsOff: return "motors off";
    case FloorImu::kIdle: return "idle";
    case FloorImu::kHandHeld: return "hand-held";
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
  if (floor == FloorImu::kIdle || floor == FloorImu::kHandHeld) {
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
  // a faster IMU than the log: interpolated first, so that the vibration is drawn at the new rate (S24)
  const bool faster = sig.rate_hz > 0.0 && sig.rate_hz * meanPeriod(flight.gyro) > 1.05;
  if (faster) {
    interpolate(flight.gyro, sig.rate_hz);
    interpolate(flight.acc, sig.rate_hz);
  }
  std::mt19937_64 rng(seed);
  // the hand's draws come from a stream of their own: the other signatures' draws stay as they were
  std::optional<HandWobble> hand;
  if (sig.floor == FloorImu::kHandHeld) {
    std::mt19937_64 hand_rng(seed ^ 0x68616e64ULL);
    hand.emplace(sig.floor_gyro_vib_rms_radps, phaseEdges(flight.pose, floor_z, sig.air_height_m), hand_rng);
  }
  applyToStream(flight.gyro, sig, true, flight.pose, floor_z, hand ? &*hand : nullptr, rng);
  applyToStream(flight.acc, sig, false, flight.pose, floor_z, hand ? &*hand : nullptr, rng);
  if (sig.rate_hz > 0.0 && !faster) {
    const auto factor =
        static_cast<std::size_t>(std::max(1.0, std::round(1.0 / (sig.rate_hz * meanPeriod(flight.gyro)))));
    decimate(flight.gyro, factor);
    decimate(flight.acc, factor);
  }
  for (ImuSample& x : flight.gyro) x.t_s += sig.lag_s;
  for (ImuSample& x : flight.acc) x.t_s += sig.lag_s;
}

}  // namespace uwb::sim
