/** @file FlightSimulator.cpp
 *  @brief IMU, pose and TDoA2 streams of one simulated flight: docs/math/simulation.md (S9)–(S20).
 */
#include "uwb/sim/FlightSimulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "uwb/io/Airborne.h"
#include "uwb/model/TdoaModel.h"
#include "uwb/sim/Kinematics.h"

namespace uwb::sim {
namespace {

/// (S8) The least thrust, as a fraction of hover, a simulated path may ask for.
constexpr double kMinThrustFraction = 0.05;

double quantize(double v, double q) { return q > 0.0 ? std::round(v / q) * q : v; }

/// Independent random streams derived from one seed, so that e.g. disabling outliers leaves the IMU noise alone.
struct Streams {
  std::mt19937_64 bias_field;
  std::mt19937_64 imu;
  std::mt19937_64 schedule;
  std::mt19937_64 tdoa_error;
};

Streams makeStreams(std::uint64_t seed) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed & 0xffffffffu), static_cast<std::uint32_t>(seed >> 32),
                    0x75776274u /* "uwbt" */};
  std::array<std::uint32_t, 8> w{};
  seq.generate(w.begin(), w.end());
  const auto word = [&](std::size_t i) { return (static_cast<std::uint64_t>(w[2 * i]) << 32) | w[2 * i + 1]; };
  return Streams{std::mt19937_64(word(0)), std::mt19937_64(word(1)), std::mt19937_64(word(2)),
                 std::mt19937_64(word(3))};
}

}  // namespace

const std::vector<std::string>& utilFlightColumns() {
  static const std::vector<std::string> kColumns = {
      "t_tdoa", "idA",    "idB",    "tdoa_meas", "t_acc",  "acc_x",  "acc_y",  "acc_z",   "t_gyro",
      "gyro_x", "gyro_y", "gyro_z", "t_tof",     "tof",    "t_flow", "deltaX", "deltaY",  "t_baro",
      "baro",   "t_pose", "pose_x", "pose_y",    "pose_z", "pose_qx", "pose_qy", "pose_qz", "pose_qw"};
  return kColumns;
}

namespace {

// --- IMU (S10), (S11): truth + bias (turn-on + random walk) + white noise.
void simulateImu(const Trajectory& trajectory, const Scenario& scenario, const SimParams& params, std::mt19937_64& rng,
                 SimResult& out) {
  Flight& flight = out.flight;
  const ImuParams& ip = params.imu;
  const double dt = 1.0 / ip.rate_hz;
  const auto n = static_cast<std::size_t>(std::floor(trajectory.duration_s() * ip.rate_hz)) + 1;
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto randn3 = [&] { return Vec3(normal(rng), normal(rng), normal(rng)); };
  Vec3 b_acc = ip.acc_bias_std_mps2 * randn3();
  Vec3 b_gyro = ip.gyro_bias_std_rps * randn3();
  const double acc_rw = ip.acc_bias_rw_mps2_sqrt_s * std::sqrt(dt);
  const double gyro_rw = ip.gyro_bias_rw_rps_sqrt_s * std::sqrt(dt);
  flight.acc.reserve(n);
  flight.gyro.reserve(n);
  out.imu_truth.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    const KinematicState s = kinematicState(trajectory, t, params.rotor_drag_per_s);
    // (S8) a quadrotor's thrust points along body z and cannot pull: a path that brakes a climb (or speeds a descent)
    // faster than gravity would turn the simulated body over within milliseconds
    if (s.w_a.z() + kGravity_mps2 < kMinThrustFraction * kGravity_mps2)
      throw std::invalid_argument(
          "simulateFlight: the " + toString(scenario.trajectory.shape) + " path asks for a vertical acceleration of " +
          std::to_string(s.w_a.z()) + " m/s² at t = " + std::to_string(t) + " s, below " +
          std::to_string((kMinThrustFraction - 1.0) * kGravity_mps2) +
          " m/s² (a thrust under " + std::to_string(kMinThrustFraction) +
          " g, which a quadrotor cannot fly): lengthen trajectory.takeoff_s / landing_s or slow the pattern");
    // (S10) rotor vibration only while flying; the draws are the same either way (one rng sequence)
    const Vec3 acc_noise = (s.on_ground ? ip.rest_acc_noise_std_mps2 : ip.acc_noise_std_mps2) * randn3();
    const Vec3 gyro_noise = (s.on_ground ? ip.rest_gyro_noise_std_rps : ip.gyro_noise_std_rps) * randn3();
    flight.acc.push_back({t, s.b_specific_force + b_acc + acc_noise});
    flight.gyro.push_back({t, s.b_omega + b_gyro + gyro_noise});
    out.imu_truth.push_back({s.b_specific_force, s.b_omega, b_acc, b_gyro});
    b_acc += acc_rw * randn3();
    b_gyro += gyro_rw * randn3();
  }
}

// --- Ground-truth pose (Vicon-like), optionally quantized.
void simulatePose(const Trajectory& trajectory, const SimParams& params, SimResult& out) {
  Flight& flight = out.flight;
  const PoseParams& pp = params.pose;
  const auto n = static_cast<std::size_t>(std::floor(trajectory.duration_s() * pp.rate_hz)) + 1;
  flight.pose.reserve(n);
  out.pose_exact.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / pp.rate_hz;
    const KinematicState s = kinematicState(trajectory, t, params.rotor_drag_per_s);
    out.pose_exact.push_back({t, s.w_p, s.w_q_b});
    PoseSample q{t, s.w_p, s.w_q_b};
    for (int i = 0; i < 3; ++i) q.w_p_b[i] = quantize(q.w_p_b[i], pp.position_quantum_m);
    if (pp.quat_quantum > 0.0) {
      for (int i = 0; i < 4; ++i) q.w_q_b.coeffs()[i] = quantize(q.w_q_b.coeffs()[i], pp.quat_quantum);
      q.w_q_b.normalize();
    }
    flight.pose.push_back(q);
  }
}

// --- TDoA2 (S19), (S20): neighbour pairs in round robin at a jittered rate; TDoA3 (S19b): random pairs.
// out.survey holds the anchors sorted by id.
void simulateTdoa(const Trajectory& trajectory, const Scenario& scenario, const SimParams& params,
                  const SimulatedBias& bias, Streams& rng, SimResult& out) {
  Flight& flight = out.flight;
  const AnchorSurvey& survey = out.survey;
  const double duration = trajectory.duration_s();
  const double ground_z = scenario.trajectory.ground_z_m;
  const TdoaScheduleParams& tp = params.tdoa;
  const double dt = 1.0 / tp.rate_hz;
  std::uniform_real_distribution<double> jitter(-tp.jitter_fraction, tp.jitter_fraction);
  std::uniform_real_distribution<double> phase(0.0, 1.0);
  const std::size_t n_anchors = survey.anchors.size();  // sorted by id
  const auto n_expected = static_cast<std::size_t>(duration * tp.rate_hz * 1.05) + 16;
  flight.tdoa.reserve(n_expected);
  out.tdoa_truth.reserve(n_expected);
  std::size_t slot = static_cast<std::size_t>(phase(rng.schedule) * static_cast<double>(n_anchors)) % n_anchors;
  double t = dt * phase(rng.schedule);
  if (tp.tdoa3 && n_anchors < 2) throw std::invalid_argument("simulateFlight: TDoA3 needs at least two anchors");
  std::uniform_int_distribution<std::size_t> any_anchor(0, n_anchors - 1), other_anchor(1, n_anchors - 1);
  while (t <= duration) {
    std::size_t i_a = slot, i_b = (slot + 1) % n_anchors;
    if (tp.tdoa3) {
      // (S19b) the anchor just heard against a random other one heard before it
      i_b = any_anchor(rng.schedule);
      i_a = (i_b + other_anchor(rng.schedule)) % n_anchors;
    }
    const Anchor& anchor_a = survey.anchors[i_a];
    const Anchor& anchor_b = survey.anchors[i_b];
    const KinematicState s = kinematicState(trajectory, t, params.rotor_drag_per_s);
    const Vec3 w_p_tag = tagPosition(s.w_p, s.w_q_b, params.b_t_tag);
    TdoaTruth truth;
    truth.tdoa_true_m = range(w_p_tag, anchor_b.w_p) - range(w_p_tag, anchor_a.w_p);  // (S20)
    truth.error = bias.sample(t, anchor_a.id, anchor_b.id, w_p_tag, s.w_q_b, s.w_p.z() - ground_z, rng.tdoa_error);
    truth.on_ground = s.on_ground;
    truth.airborne = isAirborne(s.w_p.z());
    flight.tdoa.push_back({t, anchor_a.id, anchor_b.id, truth.tdoa_true_m + truth.error.total()});
    out.tdoa_truth.push_back(truth);
    slot = (slot + 1) % n_anchors;
    t += dt * (1.0 + jitter(rng.schedule));
  }
}

}  // namespace

SimResult simulateFlight(const Scenario& scenario, const SimParams& params, std::uint64_t seed) {
  params.validate();
  const Trajectory trajectory(scenario.trajectory);  // validates the trajectory params
  AnchorSurvey survey = scenario.survey;
  std::sort(survey.anchors.begin(), survey.anchors.end(), [](const Anchor& a, const Anchor& b) { return a.id < b.id; });
  if (survey.anchors.size() < 2) throw std::invalid_argument("simulateFlight: the survey needs at least 2 anchors");

  Streams rng = makeStreams(seed);
  // (S12) the hardware and room from bias.field_seed when set, else from the flight's seed
  std::mt19937_64 field_rng =
      params.bias.field_seed != 0 ? makeStreams(params.bias.field_seed).bias_field : std::mt19937_64{};
  const SimulatedBias bias(params.bias, survey, params.bias.field_seed != 0 ? field_rng : rng.bias_field, rng.bias_field);

  SimResult out;
  out.survey = survey;
  Flight& flight = out.flight;
  flight.pose_has_orientation = true;
  flight.source = "simulated " + toString(scenario.trajectory.shape) + " (seed " + std::to_string(seed) + ")";
  if (params.write_full_util_header) flight.columns = utilFlightColumns();

  simulateImu(trajectory, scenario, params, rng.imu, out);
  simulatePose(trajectory, params, out);
  simulateTdoa(trajectory, scenario, params, bias, rng, out);
  return out;
}

}  // namespace uwb::sim
