/** @file Multilateration.h
 *  @brief Start without ground truth: robust Gauss–Newton TDoA multilateration of a position from a batch of
 *         measurements taken while the body moved by known displacements (docs/math/filter.md F16).
 */
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "uwb/filter/TdoaUpdate.h"

namespace uwb {

/// One measurement of the batch: the TDoA and the body displacement d_i since the reference instant, so the body
/// was at p0 + d_i when it was taken (d_i from IMU integration; zero for a static body).
struct MultilaterationSample {
  TdoaMeasurement z;
  Vec3 w_d_b = Vec3::Zero();
  Quat w_q_b = Quat::Identity();  ///< attitude when measured (lever arm)
};

struct MultilaterationResult {
  Vec3 w_p0 = Vec3::Zero();         ///< body origin at the reference instant [m]
  Vec3 w_v0 = Vec3::Zero();         ///< body velocity at the reference instant [m/s] (multilaterateMoving only)
  Eigen::Matrix<double, 6, 6> covariance_pv = Eigen::Matrix<double, 6, 6>::Identity();  ///< joint (p0, v0) covariance [m², m²/s] (multilaterateMoving only)
  Mat3 covariance = Mat3::Identity();  ///< (JᵀWJ)⁻¹ σ̂² [m²]
  double rms_residual_m = 0.0;      ///< robustly weighted RMS residual
  int iterations = 0;
  std::size_t n_used = 0;
  /// (F16f, multilaterateOnFloorWithDelays only) the range delay found for each floor-level anchor, indexed by anchor
  /// id; NaN for an anchor whose delay was not solved for (not floor-level, or not seen) [m]
  std::vector<double> anchor_delay_m;
};

/// (F16k) A TDoA position fix needs three independent differences, four anchors, in the air; on a floor of known
/// height two suffice, three anchors. With fewer the solve is free along a curve and its covariance a fiction.
constexpr int minFixAnchors(bool on_floor) { return on_floor ? 3 : 4; }

/// The distinct anchor ids of a set of TDoA pairs, counted against minFixAnchors (F16k). Holds up to 128 ids.
class DistinctAnchors {
 public:
  void add(int id_a, int id_b) {
    insert(id_a);
    insert(id_b);
  }
  int count() const { return n_; }

 private:
  void insert(int id);
  std::array<int, 128> ids_{};
  int n_ = 0;
};

/// Huber-IRLS Gauss–Newton on p0 (F16), started from each of `initial_guesses`; returns the lowest-cost solution,
/// or nullopt when fewer than 4 usable samples or no start converges.
std::optional<MultilaterationResult> multilaterate(const std::vector<MultilaterationSample>& samples,
                                                   const AnchorTable& anchors, const Vec3& b_t_tag,
                                                   const std::vector<Vec3>& initial_guesses,
                                                   double huber_k_m = 0.3, int max_iterations = 30);

/// (F16c) multilaterate() for a body known to sit on the floor: the body origin's height is floor_z_m, the solve is
/// over x and y (the TDoA bias near the floor is largest along z). `covariance` has zero z row and column.
std::optional<MultilaterationResult> multilaterateOnFloor(const std::vector<MultilaterationSample>& samples,
                                                          const AnchorTable& anchors, const Vec3& b_t_tag,
                                                          const std::vector<Vec3>& initial_guesses, double floor_z_m,
                                                          double huber_k_m = 0.3, int max_iterations = 30);

/// (F16f) multilaterateOnFloor() for a body on the floor that sees the floor-level anchors (floor_level[id] != 0) by
/// a path longer than the direct one: each such anchor's range carries its own unknown delay g_i, solved for with
/// x and y (the body at p0 + d_i as above; model z = h(p) + g_B − g_A, delays with a weak N(0, (5 m)²) prior). The
/// position then rests on the other anchors. nullopt when fewer than 3 other anchors are seen in the batch (x and y
/// are not determined by them; use multilaterateOnFloor), no start converges, or a delay falls outside
/// [kMinFloorDelay_m, kMaxFloorDelay_m].
constexpr double kMinFloorDelay_m = -1.0;  ///< a delay is a longer path: ≥ 0 up to the estimation error
constexpr double kMaxFloorDelay_m = 6.0;   ///< at most a room's size (util-pilot floors: 0.6–4.1 m)
std::optional<MultilaterationResult> multilaterateOnFloorWithDelays(
    const std::vector<MultilaterationSample>& samples, const AnchorTable& anchors, const Vec3& b_t_tag,
    const std::vector<Vec3>& initial_guesses, double floor_z_m, const std::vector<unsigned char>& floor_level,
    double huber_k_m = 0.3, int max_iterations = 30);

/// (F16b) The same robust solve for a body that moves at an unknown constant velocity on top of the known displacements:
/// the body was at p0 + v0 (t_i − t_ref) + d_i. Unknowns p0 and v0 (6), so a start in the air with unknown velocity
/// needs no ground phase. `covariance` holds the p0 block of covariance_pv. nullopt when fewer than 8 usable samples,
/// the samples span less than 0.1 s, or no start converges.
std::optional<MultilaterationResult> multilaterateMoving(const std::vector<MultilaterationSample>& samples,
                                                         const AnchorTable& anchors, const Vec3& b_t_tag,
                                                         const std::vector<Vec3>& initial_guesses, double t_ref_s,
                                                         double huber_k_m = 0.3, int max_iterations = 30);

}  // namespace uwb
