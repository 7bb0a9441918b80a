/** @file SimulatedBias.h
 *  @brief Simulated UWB range bias of each anchor and the TDoA error built from it.
 *
 *  Range bias of anchor i seen from the tag (u = unit direction tag→anchor in the body frame):
 *    β_i = c_i + h_tag(u) + h_i(u) + n(u) + m_i(p_tag)                                   (S12)
 *  with per-anchor offsets c_i, the tag antenna pattern h_tag (real spherical harmonics, common to all anchors),
 *  a smaller per-anchor pattern h_i, body occlusion n (NLOS, positive, anchor below the rotor plane), and a
 *  fine-scale multipath field m_i over the tag position (random Fourier features; repeatable in space but not a
 *  function of the body-frame direction, so the paper's GP cannot learn it). TDoA error:
 *    e = β_B − β_A + ν + o + g_B − g_A                                                   (S17)
 *  with white noise ν, rare heavy-tailed outliers o (single spikes and per-anchor NLOS bursts) and the ground-phase
 *  offsets g. docs/math/simulation.md.
 */
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/AnchorSurvey.h"

namespace uwb::sim {

/// Magnitudes of the simulated measurement error. Defaults chosen so that the airborne residuals resemble the
/// util-pilot flights (median ≈ 0, mean absolute deviation ≈ 0.16 m, per-pair medians within ±0.1 m,
/// autocorrelation ≈ 0.6 at 0.1 s); see docs/math/simulation.md, "Calibration".
struct BiasParams {
  bool enabled = true;                    ///< false: noise-free TDoA (every term below off)
  /// Seed of the hardware and the room: the tag and anchor antenna patterns, the anchor offsets and the multipath
  /// fields (S12–S15). 0 (default): drawn from the flight's own seed, so each flight has its own. Flights that share
  /// a non-zero field_seed share them, as real training and test flights with one drone in one arena do; their
  /// noise, outliers, bursts and ground offsets still follow the flight seed.
  std::uint64_t field_seed = 0;
  // learnable part: depends on the body-frame anchor direction only (the paper's GP inputs)
  double antenna_rms_m = 0.07;            ///< RMS over the sphere of the common tag pattern h_tag (S13)
  int antenna_degree = 3;                 ///< highest spherical-harmonic degree, 1..3
  double anchor_pattern_rms_m = 0.03;     ///< RMS of each anchor's own pattern h_i (S13)
  double anchor_offset_std_m = 0.02;      ///< per-anchor constant offset c_i ~ N(0, σ²)
  double nlos_bias_m = 0.05;              ///< body occlusion bias at full shadow (S14)
  double nlos_elevation_rad = -0.09;      ///< shadow starts below this body-frame elevation (≈ −5°)
  double nlos_width_rad = 0.26;           ///< elevation band over which the shadow fades in (≈ 15°)
  double nlos_azimuth_gain = 0.5;         ///< relative extra shadow toward nlos_azimuth_rad (battery)
  double nlos_azimuth_rad = kPi;          ///< body-frame azimuth of the battery bulge (behind)
  // not learnable from body-frame directions
  double multipath_std_m = 0.11;          ///< std of each anchor's spatial multipath field m_i (S15)
  double multipath_length_m = 0.3;       ///< its correlation length
  int multipath_features = 32;            ///< random Fourier features per anchor
  double noise_std_m = 0.09;              ///< white TDoA noise ν
  double outlier_probability = 0.005;     ///< probability of an independent outlier spike per measurement
  double outlier_scale_m = 0.5;           ///< outlier = ± scale · |t_ν| (sign: which anchor is delayed) (S16)
  double outlier_dof = 2.0;               ///< Student-t degrees of freedom ν
  double outlier_max_m = 4.0;            ///< outliers (spikes and bursts) are clipped to this magnitude
  // NLOS bursts (S16b): an anchor's first path is blocked for a while, so its range is too long for a stretch of
  // consecutive measurements (real outliers come in bursts; independent spikes would destroy the autocorrelation)
  double burst_probability = 0.015;        ///< probability that an anchor is in a burst in a given time bin
  double burst_length_s = 0.4;            ///< time bin (burst) length [s]
  double burst_scale_m = 0.4;             ///< burst range excess = scale · |t₂| (Student-t, ν = 2), clipped
  // ground phase (SOURCE.md Caveats: each pair off by a steady amount up to ±3.9 m while on the ground)
  bool ground_effect = true;
  double ground_low_anchor_z_m = 1.0;     ///< anchors below this height count as "low"
  double ground_low_min_m = 2.0;          ///< low anchors: ground range bias ~ U(min, max)
  double ground_low_max_m = 3.6;
  double ground_high_abs_m = 0.3;         ///< other anchors: ~ U(−abs, abs)
  double ground_noise_std_m = 0.05;       ///< extra scatter on the ground
  double ground_blend_height_m = 0.12;    ///< offset fades out between 0 and this height above the ground (S18)

  /// Throws std::invalid_argument naming the offending field.
  void validate() const;
};

/// Error components of one simulated TDoA measurement (all in metres, TDoA convention B − A).
struct TdoaErrorParts {
  double pattern_m = 0.0;    ///< (c + h_tag + h_i + n)_B − (…)_A: a function of the body-frame directions
  double multipath_m = 0.0;  ///< m_B − m_A
  double noise_m = 0.0;      ///< ν
  double outlier_m = 0.0;    ///< o: spike + (burst_B − burst_A); 0 unless an outlier
  double ground_m = 0.0;     ///< ground-phase offset (0 when airborne)
  double total() const { return pattern_m + multipath_m + noise_m + outlier_m + ground_m; }
};

/// Random draw of the bias field (coefficients, offsets, ground offsets); immutable afterwards.
class SimulatedBias {
 public:
  /// Draws all coefficients from `rng` (seeded by the caller). Anchors are addressed by survey id.
  SimulatedBias(const BiasParams& params, const AnchorSurvey& survey, std::mt19937_64& rng)
      : SimulatedBias(params, survey, rng, rng) {}
  /// The hardware and room terms (patterns, offsets, multipath: S12–S15) from `field_rng`, the flight's own terms
  /// (ground offsets S18, burst schedule S16b) from `flight_rng`. With one generator for both, the draws are those
  /// of the constructor above.
  SimulatedBias(const BiasParams& params, const AnchorSurvey& survey, std::mt19937_64& field_rng,
            std::mt19937_64& flight_rng);

  /// Deterministic range bias part (c_i + h_tag + h_i + n) for anchor id seen along body-frame unit vector
  /// b_u (tag → anchor) (S12–S14).
  double patternBias(int anchor_id, const Vec3& b_u) const;
  /// Multipath field m_i at the tag position (S15).
  double multipathBias(int anchor_id, const Vec3& w_p_tag) const;
  /// Ground range bias g_i (before the height blend).
  double groundBias(int anchor_id) const;
  /// NLOS burst range excess of anchor id at time t_s (≥ 0; 0 outside a burst) (S16b). Deterministic in t.
  double burstBias(int anchor_id, double t_s) const;
  /// Height blend weight w(h) ∈ [0, 1] of the ground offset, h = height above the ground (S18).
  double groundWeight(double height_m) const;

  /// The full error of one TDoA measurement at time t_s between anchors a and b (S17). Draws noise and spikes
  /// from rng; bursts are a deterministic function of (anchor, t_s).
  TdoaErrorParts sample(double t_s, int id_a, int id_b, const Vec3& w_p_tag, const Quat& w_q_b, double height_m,
                        std::mt19937_64& rng) const;

  const BiasParams& params() const { return params_; }

 private:
  struct AnchorTerms {
    int id = 0;
    Vec3 w_p = Vec3::Zero();
    double offset_m = 0.0;
    std::vector<double> pattern_coeffs;  ///< per-anchor SH coefficients
    std::vector<Vec3> mp_freq;           ///< multipath wave vectors [rad/m]
    std::vector<double> mp_phase;
    double ground_m = 0.0;
    std::uint64_t burst_key = 0;  ///< hash key of this anchor's burst sequence
    double burst_phase = 0.0;     ///< offset of its time bins, in bins
  };
  const AnchorTerms& terms(int id) const;

  BiasParams params_;
  std::vector<double> tag_coeffs_;
  std::vector<AnchorTerms> anchors_;
};

/// Real orthonormal spherical harmonics Y_lm(u) for l = 0..3: 16 values ordered (l, m) = (0,0), (1,−1), (1,0),
/// (1,1), (2,−2), …, (3,3) (S13). u must be a unit vector. ∫ Y_lm Y_l'm' dΩ = δ.
std::array<double, 16> realSphericalHarmonics(const Vec3& u);

}  // namespace uwb::sim
