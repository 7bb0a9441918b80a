/** @file FlightMode.h
 *  @brief The flight-mode supervisor: at rest on the floor, in floor contact with the motors running, or airborne, as
 *         a discrete state whose evidence comes from every sensor (docs/math/filter.md F29).
 *
 *  Each sensor's evidence is a log-likelihood ratio of "airborne" against "on the floor", bounded by how far that
 *  sensor can be trusted:
 *   - the IMU (F29a): rest and floor shaking from RestDetector, the climb of the take-off detector; its log-odds move
 *     at a bounded rate and never exceed ±imu_max_log_odds, so the IMU alone can hold a mode but never against strong
 *     evidence of another sensor. Floor shaking counts only when it stands out against the shaking this flight shows
 *     in the air, which the supervisor learns (F29b), not against a constant of one drone;
 *   - the TDoA (F29c): the heights above the floor at which a window of recent TDoA puts the tag, from each TDoA's
 *     residual and vertical sensitivity at the estimate, once as TDoA in the air and once corrected as on the floor
 *     (the floor-level anchors' delays, F16f): whichever hypothesis explains its window more tightly (about a height
 *     in the flight range, or about the floor) wins. Its log-likelihood ratio is bounded by tdoa_max_log_odds for
 *     the air and by the smaller tdoa_max_floor_log_odds for the floor;
 *   - the downward range (F29f), when the log has one: the same two hypotheses on a window of the heights it
 *     measures directly, within the TDoA's bounds.
 *  The mode is airborne while the sum is positive (with a hysteresis), on the floor otherwise; rest and contact are
 *  told apart by the IMU. Nothing is decided for good: the evidence is re-weighed at every step.
 *
 *  One status word (status()) holds the mode and the evidence behind it, in the manner of the Crazyflie supervisor's
 *  state and PX4's estimator control status; doubts (the IMU held the floor while the TDoA put the tag in the air)
 *  are counted for the run's warnings. No allocation.
 */
#pragma once

#include <cstdint>
#include <string>

namespace uwb {

enum class FlightMode : unsigned char {
  kRest,      ///< on the floor, motors off (still IMU)
  kContact,   ///< on the floor with the motors running (shaking IMU)
  kAirborne,  ///< flying, or carried
};
std::string toString(FlightMode mode);

/// Bits of FlightModeSupervisor::status().
enum FlightModeStatus : std::uint32_t {
  kModeRest = 1u << 0,
  kModeContact = 1u << 1,
  kModeAirborne = 1u << 2,
  kImuSaysRest = 1u << 3,          ///< the IMU's rest test holds now
  kImuSaysContact = 1u << 4,       ///< floor shaking above the flight's learned airborne level
  kImuSaysClimb = 1u << 5,         ///< the take-off detector sees a climb
  kTdoaHeightValid = 1u << 6,      ///< the TDoA window holds enough vertical information
  kTdoaSaysAirborne = 1u << 7,     ///< the TDoA's Bayes factor favours the air
  kTdoaOverrulesImu = 1u << 8,     ///< the mode follows the TDoA against the IMU
  kAirShakeLearned = 1u << 9,      ///< the flight's airborne shaking level has been measured
  kInconsistent = 1u << 10,        ///< the innovation consistency check fails (set by the estimator, F30)
  kTofSaysAirborne = 1u << 11,     ///< the downward range's Bayes factor favours the air (F29f)
};

struct FlightModeParams {
  double imu_max_log_odds = 4.0;        ///< bound of the IMU's log-odds from shaking and climbs L_IMU [nats] (F29a)
  double imu_rest_log_odds = 24.0;      ///< bound of the IMU's log-odds towards the floor at rest L_rest [nats] (F29a)
  double imu_rate_per_s = 100.0;        ///< rate r at which the IMU's log-odds move [nats/s] (F29a)
  double tdoa_max_log_odds = 20.0;      ///< bound of the TDoA's Bayes factor for the air [nats] (F29c)
  double tdoa_max_floor_log_odds = 2.0; ///< bound of the TDoA's Bayes factor for the floor [nats] (F29c, F29d)
  double tdoa_window_s = 0.5;           ///< forgetting time τ of the TDoA height window [s] (F29c)
  double tdoa_min_effective = 30.0;     ///< forgotten TDoA count below which the window says nothing (F29c)
  double tdoa_independent = 10.0;       ///< independent TDoA per window, their errors being correlated (F29c)
  double min_vertical_gain = 0.2;       ///< |∂h/∂z| below which a TDoA says nothing of the height (F29c)
  double height_floor_sigma_m = 0.3;    ///< spread σ added to both hypotheses' mean squares [m] (F29c)
  double air_min_height_m = 0.3;        ///< lowest flight height above the floor of the air hypothesis [m] (F29c)
  double air_max_height_m = 3.0;        ///< highest flight height above the floor of the air hypothesis [m] (F29c)
  double hysteresis_log_odds = 1.0;     ///< a mode is left when the summed log-odds pass ∓ this h [nats] (F29)
  double air_shake_ratio = 4.0;         ///< floor shaking: mean square above this κ × the airborne level (F29b)
  double air_shake_prior_ms = 0.075 * 0.075;  ///< airborne shaking level before it is measured [rad²/s²] (F29b)
  double air_shake_tau_s = 3.0;         ///< time constant of the learned airborne shaking level [s] (F29b)
  double tof_window_s = 0.2;            ///< forgetting time of the downward range's height window [s] (F29f)
  double tof_min_effective = 3.0;       ///< forgotten range count below which that window says nothing (F29f)
  double tof_height_sigma_m = 0.05;     ///< spread σ added to both hypotheses' mean squares of its heights [m] (F29f)
  void validate() const;
};

/// The IMU's evidence at one step (F29a), from RestDetector and the take-off detector.
struct ImuModeEvidence {
  bool rest = false;            ///< at rest (and near the floor, where the estimator asks for it)
  bool shaking_near_floor = false;  ///< floor-contact shaking where contact is plausible
  bool climbing = false;        ///< the take-off detector's climb
  double shake_ms_radps2 = 0.0; ///< high-passed gyro mean square (RestDetector::gyroHighPassMeanSquare)
};

class FlightModeSupervisor {
 public:
  explicit FlightModeSupervisor(const FlightModeParams& params = {});

  /// Starts in a mode, the evidence cleared; the learned airborne shaking level is kept.
  void reset(FlightMode mode);
  /// Floor shaking against the learned airborne level (F29b): is this mean square contact evidence?
  bool shakingStandsOut(double shake_ms_radps2) const;
  /// Folds in the IMU's evidence over dt_s (F29a) and learns the airborne shaking level while airborne (F29b).
  void addImu(double t_s, double dt_s, const ImuModeEvidence& evidence, bool settled_in_air);
  /// One TDoA (F29c): its residual at the estimate r = z̃ − h(x̂) [m] as a TDoA in the air and as one on the floor
  /// (corrected by the floor-level delays; the same without them), its vertical sensitivity ∂h/∂z, and the
  /// estimate's height above the floor [m].
  void addTdoa(double t_s, double residual_air_m, double residual_floor_m, double dh_dz, double estimate_height_m);
  /// The TDoA window is cleared (a re-acquisition: the estimate is not a linearization point).
  void clearTdoa();
  /// One downward range (F29f): the height of the body above the floor that it measures [m].
  void addTof(double t_s, double height_m);
  /// Re-decides the mode from the summed evidence (F29). Returns true when the mode changed.
  bool decide(double t_s);
  /// The TDoA put the tag in the air against the IMU's floor evidence: the shaking seen now is airborne shaking
  /// (F29b); the level is raised to it.
  void learnAirShake(double shake_ms_radps2);

  FlightMode mode() const { return mode_; }
  bool onFloor() const { return mode_ != FlightMode::kAirborne; }
  double imuLogOdds() const { return imu_log_odds_; }
  /// The TDoA's Bayes factor airborne : floor, 0 while the window is not valid (F29c) [nats].
  double tdoaLogOdds() const { return tdoa_log_odds_; }
  /// The TDoA window's mean height above the floor as TDoA in the air, and its spread [m] (NaN while not valid).
  double tdoaHeight() const { return tdoa_height_m_; }
  double tdoaHeightSpread() const { return tdoa_height_spread_m_; }
  /// The downward range's Bayes factor airborne : floor (0 while its window is not valid), its window's mean height
  /// above the floor and spread [m] (NaN while not valid) (F29f).
  double tofLogOdds() const { return tof_log_odds_; }
  double tofHeight() const { return tof_height_m_; }
  double tofHeightSpread() const { return tof_height_spread_m_; }
  double airShakeLevel() const { return air_shake_ms_; }
  std::uint32_t status() const;
  /// Time the mode was on the floor while the TDoA window said airborne (log-odds above tdoa_max_floor_log_odds)
  /// [s], and the largest TDoA height meanwhile [m]: what the run's warnings name before they blame the survey.
  double doubtedFloorTime() const { return doubted_floor_s_; }
  double doubtedFloorMaxHeight() const { return doubted_floor_max_height_m_; }
  /// Mode changes the TDoA forced against the IMU.
  int tdoaOverrules() const { return n_tdoa_overrules_; }

 private:
  void updateTdoaFactor();
  /// Re-weighs the downward range's window (F29f).
  void updateTofFactor();
  /// Drops the range's window when no reading came for kTofStaleWindows forgetting times (F29f).
  void dropStaleTof(double t_s);
  static constexpr double kTofStaleWindows = 5.0;
  /// ½ min(n, tdoa_independent) [log(m_floor + σ²) − log(m_air + σ²)] with m_air = s²_air + d², d the distance of h_air
  /// from the flight range, clamped to [−tdoa_max_floor_log_odds, tdoa_max_log_odds] (F29c, F29f).
  double heightLogOdds(double n, double h_air, double s2_air, double ms_floor, double sigma_m) const;

  FlightModeParams params_;
  FlightMode mode_ = FlightMode::kAirborne;
  double imu_log_odds_ = 0.0, tdoa_log_odds_ = 0.0;
  bool imu_rest_ = false, imu_contact_ = false, imu_climb_ = false;
  /// A window of heights: forgotten sums of w, w·h, w·h² with w = (∂h/∂z)² (F29c).
  struct HeightWindow {
    double sw = 0.0, swh = 0.0, swhh = 0.0;
    void scale(double a) { sw *= a, swh *= a, swhh *= a; }
    void add(double w, double h) { sw += w, swh += w * h, swhh += w * h * h; }
    double mean() const { return swh / sw; }
    double spread2() const;  ///< weighted variance about the mean
  };
  double t_tdoa_ = -1e300, n_ = 0.0;
  HeightWindow air_, floor_;
  double tdoa_height_m_, tdoa_height_spread_m_;
  HeightWindow tof_;  ///< heights measured by the downward range, weight 1 each (F29f)
  double t_tof_ = -1e300, n_tof_ = 0.0, tof_log_odds_ = 0.0;
  double tof_height_m_, tof_height_spread_m_;
  double air_shake_ms_;
  bool air_shake_learned_ = false;
  double t_last_ = -1e300;
  double doubted_floor_s_ = 0.0, doubted_floor_max_height_m_ = 0.0;
  int n_tdoa_overrules_ = 0;
  bool overruled_ = false;
};

}  // namespace uwb
