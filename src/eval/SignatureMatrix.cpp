/** @file SignatureMatrix.cpp
 *  @brief The sensor-signature matrix of `uwbtdoa protocol --signatures` (docs/robustness.md, simulation.md S24).
 */
#include "uwb/eval/SignatureMatrix.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "uwb/eval/EstimateChecks.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/FlightSimulator.h"

namespace uwb {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kG = 9.80665;
/// Pass criteria of the matrix (the issue's "done means"): RMSE within this ratio of the plain flight's, at least this
/// fraction of the airborne TDoA at their in-flight σ, never longer than this on the floor while flying [s].
constexpr double kMaxRatio = 1.2;
constexpr double kMinInFlight = 0.95;
constexpr double kMaxStuck_s = 1.0;
/// "Stuck on the floor": estimate within this of the floor while the truth is above kStuckTruth_m [m].
constexpr double kStuckEstimate_m = 0.2;
constexpr double kStuckTruth_m = 0.5;

SignatureCell cell(std::string name, double gyro_dps, double acc_g, bool replace) {
  SignatureCell c;
  c.name = std::move(name);
  c.signature.flight_gyro_vib_rms_radps = gyro_dps * kDeg;
  c.signature.flight_acc_vib_rms_mps2 = acc_g * kG;
  c.signature.replace_flight = replace;
  return c;
}

/// A floor that shakes (idling: gyro and 0.05 g of accelerometer) or is held in a hand (S24b), gyro RMS in °/s: a cell
/// of its own, named after its floor, or the floor of the combined cell `c` (which keeps its name).
SignatureCell floorCell(sim::FloorImu floor, double gyro_dps, SignatureCell c = {}) {
  if (c.name.empty())
    c.name = "floor " + sim::toString(floor) + " " + std::to_string(static_cast<int>(gyro_dps)) + "°/s";
  c.signature.floor = floor;
  c.signature.floor_gyro_vib_rms_radps = gyro_dps * kDeg;
  if (floor == sim::FloorImu::kIdle) c.signature.floor_acc_vib_rms_mps2 = 0.05 * kG;
  return c;
}

/// Airborne TDoA by the truth (above the flight's floor level + kAirborneMinZ_m).
std::size_t airborneTdoa(const Flight& f) {
  const double floor_z = sim::truthFloorLevel(f.pose);
  std::size_t n = 0;
  for (const TdoaMeasurement& m : f.tdoa)
    if (isAirborne(sim::truthHeightAt(f.pose, m.t_s) - floor_z)) ++n;
  return n;
}

/// TDoA the run took at the floor's σ while the truth flew: the running count of each output interval, counted when
/// the truth at the interval's end is airborne.
double tdoaAtRestWhileFlying(const LocalizationRun& run, const Flight& f) {
  const double floor_z = sim::truthFloorLevel(f.pose);
  std::size_t n = 0, before = 0;
  const std::size_t m = std::min(run.trajectory.size(), run.n_tdoa_used_at_rest.size());
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t now = run.n_tdoa_used_at_rest[k];
    if (isAirborne(sim::truthHeightAt(f.pose, run.trajectory[k].t_s) - floor_z)) n += now - before;
    before = now;
  }
  return static_cast<double>(n);
}

/// Longest span of the estimate within kStuckEstimate_m of the floor while the truth flies above kStuckTruth_m.
double longestStuck(const TrajectoryMetrics& m, double floor_z) {
  double longest = 0.0, since = std::nan("");
  for (const PositionErrorSample& s : m.samples) {
    const bool stuck = s.w_p_true.z() - floor_z > kStuckTruth_m && s.w_p_est.z() - floor_z < kStuckEstimate_m;
    if (stuck && std::isnan(since)) since = s.t_s;
    if (!stuck) since = std::nan("");
    if (stuck) longest = std::max(longest, s.t_s - since);
  }
  return longest;
}

}  // namespace

std::vector<SignatureCell> signatureCells(bool transplant) {
  // a transplant replaces the flight's own vibration; a simulated flight's IMU is the simulator's white noise, to which
  // the vibration is added. The quiet accelerometer of the transplants is that of the drone of the issue (0.005 g).
  const double acc = transplant ? 0.005 : 0.0;
  std::vector<SignatureCell> cells;
  for (double g : {0.0, 5.0, 10.0, 20.0, 40.0})
    cells.push_back(cell("gyro " + std::to_string(static_cast<int>(g)) + "°/s", g, acc, transplant));
  for (double a : {0.05, 0.3}) cells.push_back(cell("acc " + std::to_string(a).substr(0, 4) + " g", 0.0, a, transplant));
  SignatureCell off;
  off.name = "floor motors off";
  off.signature.floor = sim::FloorImu::kMotorsOff;
  cells.push_back(off);
  for (double idle : {10.0, 40.0}) cells.push_back(floorCell(sim::FloorImu::kIdle, idle));
  for (double hand : {10.0, 30.0}) cells.push_back(floorCell(sim::FloorImu::kHandHeld, hand));
  for (double hz : {100.0, 500.0, 1000.0}) {
    SignatureCell c;
    c.name = "IMU " + std::to_string(static_cast<int>(hz)) + " Hz";
    c.signature.rate_hz = hz;
    cells.push_back(c);
  }
  SignatureCell gb;
  gb.name = "gyro bias 3°/s";
  gb.signature.gyro_bias_radps = Vec3(3.0, -3.0, 3.0).normalized() * 3.0 * kDeg;
  cells.push_back(gb);
  SignatureCell ab;
  ab.name = "acc bias 0.1 g";
  ab.signature.acc_bias_mps2 = Vec3(1.0, -1.0, 1.0).normalized() * 0.1 * kG;
  cells.push_back(ab);
  for (double ms : {10.0, 30.0}) {
    SignatureCell c;
    c.name = "IMU lag " + std::to_string(static_cast<int>(ms)) + " ms";
    c.signature.lag_s = ms * 1e-3;
    cells.push_back(c);
  }
  for (double g : {20.0, 40.0}) {
    // the drone of filter.md F29: motors off on the floor, gyro shaking in flight, accelerometer quiet
    SignatureCell c = cell("other drone: floor off, gyro " + std::to_string(static_cast<int>(g)) + "°/s", g, 0.005,
                           true);
    c.signature.floor = sim::FloorImu::kMotorsOff;
    cells.push_back(c);
  }
  // combined cells: the worst of several rows at once
  SignatureCell slow = cell("combined: floor off, gyro 40°/s, acc 0.3 g, 100 Hz, biases, lag 30 ms", 40.0, 0.3, true);
  slow.signature.floor = sim::FloorImu::kMotorsOff;
  slow.signature.rate_hz = 100.0;
  slow.signature.gyro_bias_radps = gb.signature.gyro_bias_radps;
  slow.signature.acc_bias_mps2 = ab.signature.acc_bias_mps2;
  slow.signature.lag_s = 0.03;
  cells.push_back(slow);
  SignatureCell idle = cell("combined: floor idle 40°/s, gyro 20°/s, 1000 Hz, lag 10 ms", 20.0, acc, transplant);
  idle = floorCell(sim::FloorImu::kIdle, 40.0, idle);
  idle.signature.rate_hz = 1000.0;
  idle.signature.lag_s = 0.01;
  cells.push_back(idle);
  SignatureCell held = cell("combined: hand-held 30°/s, gyro 20°/s, gyro bias 3°/s", 20.0, acc, transplant);
  held = floorCell(sim::FloorImu::kHandHeld, 30.0, held);
  held.signature.gyro_bias_radps = gb.signature.gyro_bias_radps;
  cells.push_back(held);
  return cells;
}

std::vector<SignatureFlight> signatureFlights(const std::string& data_dir, const std::string& only) {
  std::vector<SignatureFlight> out;
  const auto wanted = [&](const std::string& n) { return only.empty() || n.find(only) != std::string::npos; };
  for (sim::TrajectoryShape shape : {sim::TrajectoryShape::kCircle, sim::TrajectoryShape::kZigzag}) {
    const std::string name = "sim-" + sim::toString(shape) + "-s11";
    if (!wanted(name)) continue;
    const sim::Scenario sc = sim::makeScenario(sim::paperAnchors(), shape, 40.0);
    out.push_back({name, sim::simulateFlight(sc, sim::SimParams{}, 11).flight, sc.survey, false});
  }
  const std::string pilot = data_dir + "/real/util-pilot";
  for (const char* n : {"0425-traj2", "0426-traj1", "0426-traj11"}) {
    const std::string name = std::string(n) + "-transplant";
    const std::string session = std::string(n).substr(0, 4);
    const std::string path = pilot + "/" + session + "/" + n + ".csv";
    if (!wanted(name) || !std::filesystem::is_regular_file(path)) continue;
    SignatureFlight f;
    f.name = name;
    f.survey = readAnchorSurvey(pilot + "/survey/anchor_" + session + "_survey.txt");
    FlightReadOptions ro;
    ro.survey = &f.survey;
    f.flight = readFlightCsv(path, ro);
    f.transplant = true;
    out.push_back(std::move(f));
  }
  return out;
}

SignatureRow evaluateSignature(const SignatureFlight& f, const SignatureCell& c, const LocalizationRun& plain,
                               const LocalizationOptions& options, std::uint64_t seed) {
  Flight flight = f.flight;
  sim::applyImuSignature(flight, c.signature, seed);
  const LocalizationRun run = localizeFlight(flight, f.survey, options);
  SignatureRow r;
  r.flight = f.name;
  r.cell = c.name;
  r.mode_overrules = run.summary.n_mode_overrules;
  if (!run.metrics || !plain.metrics) return r;
  r.rmse_plain_m = plain.metrics->airborne.rmse_m;
  r.rmse_cell_m = run.metrics->airborne.rmse_m;
  r.ratio = r.rmse_cell_m / r.rmse_plain_m;
  const double n_air = static_cast<double>(std::max<std::size_t>(airborneTdoa(f.flight), 1));
  // the airborne TDoA (by the truth) that the cell took at the floor's σ and the plain flight did not
  const double extra_floor = tdoaAtRestWhileFlying(run, f.flight) - tdoaAtRestWhileFlying(plain, f.flight);
  r.in_flight_fraction = std::clamp(1.0 - std::max(extra_floor, 0.0) / n_air, 0.0, 1.0);
  r.longest_floor_stuck_s = longestStuck(*run.metrics, sim::truthFloorLevel(f.flight.pose));
  EstimateCheckParams cp;
  cp.floor_z_m = options.params.ground_z_m;
  r.coverage_2sigma = checkEstimate(run.trajectory, *run.metrics, cp).coverage_2sigma;
  r.pass = r.ratio <= kMaxRatio && r.in_flight_fraction >= kMinInFlight && r.longest_floor_stuck_s <= kMaxStuck_s;
  r.n_draws_pass = r.pass ? 1 : 0;
  return r;
}

std::uint64_t signatureSeed(const std::string& flight, const std::string& cell, int draw) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bit
  const auto mix = [&h](unsigned char byte) { h = (h ^ byte) * 1099511628211ull; };
  for (const char ch : flight + "/" + cell + "#" + std::to_string(draw)) mix(static_cast<unsigned char>(ch));
  return h;
}

SignatureRow evaluateSignatureDraws(const SignatureFlight& f, const SignatureCell& c, const LocalizationRun& plain,
                                    const LocalizationOptions& options, int draws) {
  if (draws < 1) throw std::invalid_argument("signature matrix: draws must be ≥ 1, got " + std::to_string(draws));
  SignatureRow worst = evaluateSignature(f, c, plain, options, signatureSeed(f.name, c.name, 0));
  for (int d = 1; d < draws; ++d) {
    const SignatureRow r = evaluateSignature(f, c, plain, options, signatureSeed(f.name, c.name, d));
    worst.rmse_cell_m = std::max(worst.rmse_cell_m, r.rmse_cell_m);
    worst.ratio = std::max(worst.ratio, r.ratio);
    worst.in_flight_fraction = std::min(worst.in_flight_fraction, r.in_flight_fraction);
    worst.longest_floor_stuck_s = std::max(worst.longest_floor_stuck_s, r.longest_floor_stuck_s);
    worst.coverage_2sigma = worst.coverage_2sigma.cwiseMin(r.coverage_2sigma);
    worst.mode_overrules = std::max(worst.mode_overrules, r.mode_overrules);
    worst.pass = worst.pass && r.pass;
    worst.n_draws_pass += r.n_draws_pass;
  }
  worst.n_draws = draws;
  return worst;
}

}  // namespace uwb
