/** @file StartUp.h
 *  @brief Finding the position without ground truth, at the start and after a loss: TDoA collected over a short
 *         window while the filter predicts, then one robust multilateration of the position (at rest) or of position
 *         and velocity (moving: a start in the air), docs/math/filter.md F16, F16b.
 */
#pragma once

#include <optional>
#include <vector>

#include "uwb/filter/EkfParams.h"
#include "uwb/filter/Multilateration.h"
#include "uwb/filter/NavState.h"

namespace uwb {

/// The position (and velocity) found, brought to the time of the last sample.
struct StartFix {
  Vec3 w_p_b = Vec3::Zero();   ///< body origin now [m]
  Vec3 w_v_b = Vec3::Zero();   ///< body velocity now [m/s]
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Identity();  ///< of (p, v) now
  Vec3 w_p0 = Vec3::Zero();    ///< body origin at the window's reference instant t_ref_s [m]
  Vec3 w_v0 = Vec3::Zero();    ///< body velocity then (the predicted one when solved without velocity) [m/s]
  double t_ref_s = 0.0;        ///< the reference instant: start of the collection, or its last move (F16b) [s]
  double rms_residual_m = 0.0;
  bool with_velocity = false;
  /// (F16j) the start was to be on the floor (ground evidence before the first fix), but the TDoA put the body in the
  /// air: the fix is the solve in motion of the same window, and the ground evidence is refuted
  bool floor_refuted = false;
  /// (F16f) a fix on the floor: the range delay of each floor-level anchor, by anchor id (NaN: none found) [m]
  std::vector<double> anchor_delay_m;
};

struct StartUpParams {
  double window_s = 0.6;            ///< first solve after this long [s]
  std::size_t min_samples = 40;     ///< … and at least this many TDoA
  double max_window_s = 3.0;        ///< keep at most this much history while solves fail [s]
  double min_pos_sigma_m = 0.2;     ///< the fix's position std is at least this (TDoA bias, F16) [m]
  double max_pos_sigma_m = 2.0;
  double min_vel_sigma_mps = 0.15;  ///< the fix's velocity std is at least this [m/s]
  double box_margin_m = 1.0;        ///< a solution outside the anchors' box grown by this is a failed solve [m]
  /// … and, in a re-acquisition, one whose robustly weighted RMS residual is above this [m]: the TDoA do not agree on
  /// any position (garbage, a radio fault); the filter keeps predicting and the next window is tried
  double max_rms_residual_m = 1.0;
  /// (F16j) a first start on floor contact is refuted when the free solve of its window lies inside the anchors' box and
  /// the solve in motion keeps the body at least this high above the floor over the whole window [m] …
  double floor_refute_height_m = 1.2;
  /// … with an RMS residual at most this many times the floor solve's
  double floor_refute_residual_ratio = 1.5;
  double max_speed_mps = 5.0;         ///< a moving solve faster than this is a failed solve [m/s] (F16b)
  double floor_height_sigma_m = 0.1;  ///< height std of a fix on the floor [m] (F16c)

  /// The estimator's start-up: every field from its EkfParams namesake (start_*, floor_refute_*; the position std at
  /// most init_pos_sigma_m).
  static StartUpParams fromEkfParams(const EkfParams& p);
};

class StartUp {
 public:
  StartUp(const AnchorTable& anchors, const Vec3& b_t_tag, const StartUpParams& params);
  /// Starts collecting at t_s. x_ref is the predicted state then; `moving` selects the position-and-velocity solve;
  /// `reacquisition` applies max_rms_residual_m (at the first start a poor fix is better than none: the floor-level
  /// TDoA can disagree by metres, and the fix is revised in the air).
  void begin(double t_s, const NavState& x_ref, bool moving, bool reacquisition = false);
  bool active() const { return active_; }
  /// The instant the displacements are counted from (begin(), moved forward when a solve fails, F16b) [s].
  double referenceTime() const { return t_ref_; }
  /// (F16f) By anchor id, 1 for a floor-level anchor: a fix on the floor solves a range delay for each of them.
  void setFloorLevelAnchors(const std::vector<unsigned char>& floor_level) { floor_level_ = floor_level; }
  void cancel() { active_ = false; samples_.clear(); }
  /// Adds a TDoA taken while the filter's predicted state is x_now; returns the fix when a solve succeeds (the
  /// collection then ends). floor_z_m: the body sits on the floor now (ground evidence, F18) at this height of its
  /// origin, so the solve is over x and y (F16c). floor_refutable: that evidence may be refuted by the TDoA (F16j: floor
  /// contact before the first fix, not rest).
  std::optional<StartFix> add(const TdoaMeasurement& z, const NavState& x_now,
                              std::optional<double> floor_z_m = std::nullopt, bool floor_refutable = false);

 private:
  /// The window's solve: on the floor (with the floor-level delays, F16f), refuted (F16j), moving or at rest.
  struct WindowSolve {
    std::optional<MultilaterationResult> result;
    bool moving = false;         ///< position and velocity solved (F16b)
    bool floor_refuted = false;  ///< (F16j)
    bool on_floor = false;       ///< solved on the floor at a known height (F16c)
  };
  WindowSolve solveWindow(double t_now_s, std::optional<double> floor_z_m, bool floor_refutable) const;
  /// (F16b) A failed solve: the window keeps its newest part and the reference moves to now.
  void retryLater(double t_now_s, const NavState& x_now);
  /// (F16b) The solve brought to now, with floors on its stds.
  StartFix fixNow(const WindowSolve& w, double t_now_s, const NavState& x_now) const;
  /// Distinct anchors among the window's TDoA (F16k).
  int distinctAnchors() const;
  /// (F16j) The solve in motion of the window when its TDoA put the body in the air rather than on the floor at
  /// floor_z_m (on_floor: the floor solve of the same window; t_now_s: the window's last sample).
  std::optional<MultilaterationResult> refuteFloor(const MultilaterationResult& on_floor, double floor_z_m,
                                                   double t_now_s) const;

  const AnchorTable& anchors_;
  Vec3 b_t_tag_;
  StartUpParams params_;
  std::vector<Vec3> guesses_;
  Vec3 box_min_, box_max_;
  std::vector<MultilaterationSample> samples_;
  std::vector<unsigned char> floor_level_;
  bool active_ = false;
  bool moving_ = false;
  bool reacquisition_ = false;
  double t_ref_ = 0.0, t_try_ = 0.0;
  NavState x_ref_;
};

}  // namespace uwb
