/** @file AntennaBias.h
 *  @brief The tag's antenna-pattern TDoA bias, learned during the flight from the filter's own innovations
 *         (docs/math/filter.md F25a–F25e). No ground truth, no training flight.
 *
 *  Most of the Crazyflie LPS TDoA bias is the tag antenna pattern and the body occlusion: an extra delay d(u) that
 *  depends only on the direction u of the anchor in the BODY frame. A TDoA of pair (A, B) carries d(u_B) − d(u_A).
 *  d is written on the real orthonormal spherical harmonics of degrees 2…L (degree 0 cancels in the difference,
 *  degree 1 is a position offset while the body does not rotate, F25a), d(u) = φ(u)ᵀθ, and θ ~ N(0, σ² I) a priori.
 *  Each tracked TDoA is a scalar linear observation of θ through the regressor h = φ(u_B) − φ(u_A) with the filter's
 *  innovation as target and its innovation variance as noise (F25d), beside a nuisance offset ν of the filter's own
 *  position, so that θ learns only what no position explains (F25e); old evidence is forgotten towards the prior
 *  (F25c), so a flight without bias keeps θ near zero.
 *
 *  @code
 *    OnlineAntennaBias bias(AntennaBiasParams{3, 0.1, 60.0, kUtilTagOffset_b});
 *    bias.advance(t_s);                                  // forget to the TDoA's time
 *    BiasPrediction b = bias.predict(feature);           // subtract b.mean_m from the TDoA
 *    ... filter update with innovation r, variance S ...
 *    bias.learn(r, S);                                   // uses the regressor of the last predict()
 *  @endcode
 */
#pragma once

#include <Eigen/Core>

#include "uwb/core/Types.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

/// Highest spherical-harmonic degree of the antenna basis.
inline constexpr int kMaxAntennaDegree = 4;
/// Number of basis functions of degrees 2…kMaxAntennaDegree: (L + 1)² − 4.
inline constexpr int kMaxAntennaCoefficients = (kMaxAntennaDegree + 1) * (kMaxAntennaDegree + 1) - 4;

using AntennaVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxAntennaCoefficients, 1>;
/// The learner's state (θ, ν): the pattern's coefficients and the filter's position offset (F25e).
using AntennaStateVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxAntennaCoefficients + 3, 1>;
using AntennaStateMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAntennaCoefficients + 3,
                                      kMaxAntennaCoefficients + 3>;

/// Number of real spherical harmonics of degrees 2…max_degree, (L + 1)² − 4; throws std::invalid_argument unless
/// 2 ≤ max_degree ≤ kMaxAntennaDegree.
int antennaBasisSize(int max_degree);

/// (F25a) Real orthonormal spherical harmonics Y_lm(u) (∫ Y_lm Y_l'm' dΩ = δ) of degrees l = 2…max_degree, ordered
/// (2,−2), (2,−1), …, (2,2), (3,−3), …, of a unit vector b_u (body frame; not normalised here).
AntennaVec antennaBasis(const Vec3& b_u, int max_degree);

struct AntennaBiasParams {
  int max_degree = 3;           ///< L: degrees 2…L (2 ≤ L ≤ kMaxAntennaDegree)
  double prior_sigma_m = 0.1;   ///< prior std of each coefficient [m] (F25c)
  double memory_s = 0.0;        ///< time constant of the forgetting towards the prior [s]; 0: none (F25c)
  Vec3 b_t_tag = kUtilTagOffset_b;  ///< tag (antenna) position in the body frame [m]: directions are seen from it
  /// Std of the filter's own position error ν as the learner models it (F25e) [m]; 0: not modelled.
  double offset_sigma_m = 0.3;
  double offset_memory_s = 1.0;     ///< correlation time of ν [s] (F25e)
  /// Throws std::invalid_argument naming the first bad field.
  void validate() const;
};

/// The learned antenna delay d(u) = φ(u)ᵀθ and its Gaussian belief N(θ̂, P_θ) (F25b–F25e).
class OnlineAntennaBias {
 public:
  /// params.validate() is called. θ̂ = 0, P_θ = σ² I.
  explicit OnlineAntennaBias(const AntennaBiasParams& params);

  /// (F25b) Regressor of one TDoA: h = φ(u_B) − φ(u_A), u the unit direction from the tag to the anchor in the body
  /// frame (feature's b_p_a, b_p_b less the tag offset). Zero when the tag sits on an anchor.
  AntennaVec regressor(const TdoaFeature& feature) const;

  /// (F25c) Forgets towards the prior over the time since the last call: θ̂ ← e^{−Δt/τ} θ̂,
  /// P_θ ← e^{−2Δt/τ} P_θ + (1 − e^{−2Δt/τ}) σ² I. The first call only sets the clock; τ = 0 forgets nothing.
  void advance(double t_s);

  /// (F25e) ∂z/∂p of the TDoA at the feature's body origin (world frame): the learner's row of ν.
  static Vec3 positionRow(const TdoaFeature& feature);

  /// (F25b) Predicted TDoA bias hᵀθ̂ [m] and its variance hᵀ P_θ h [m²]; remembers h for learn().
  BiasPrediction predict(const TdoaFeature& feature);

  /// (F25d) Scalar Kalman update of s = (θ, ν) with the TDoA innovation r [m] (the TDoA less its prediction, the
  /// learned bias already subtracted) and its noise variance S [m²] (the caller's, e.g. κ times the filter's innovation
  /// variance): row ρ = (h, ∂z/∂p), k = P ρ / (ρᵀPρ + S), ŝ += k (r − ρᵀŝ), P −= k ρᵀ P. Uses the rows of the last
  /// predict(); nothing happens when S is not finite and positive.
  void learn(double innovation_m, double innovation_var_m2);

  /// d(u) = φ(u)ᵀθ̂ for a body-frame unit direction [m].
  double delay(const Vec3& b_u) const { return antennaBasis(b_u, params_.max_degree).dot(coefficients()); }
  AntennaVec coefficients() const { return x_.head(n_); }
  /// Covariance of (θ, ν), θ first.
  const AntennaStateMat& covariance() const { return P_; }
  /// Mean of the filter's position offset ν as the learner sees it [m] (F25e).
  Vec3 positionOffset() const { return x_.tail<3>(); }
  int size() const { return n_; }
  std::size_t numLearned() const { return n_learned_; }

 private:
  AntennaBiasParams params_;
  int n_ = 0;               ///< number of pattern coefficients
  AntennaStateVec x_;       ///< (θ, ν)
  AntennaStateMat P_;
  AntennaStateVec row_last_;  ///< (h, ∂z/∂p) of the last predict()
  double t_last_s_;
  bool has_time_ = false;
  std::size_t n_learned_ = 0;
};

}  // namespace uwb
