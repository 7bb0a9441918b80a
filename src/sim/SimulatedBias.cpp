/** @file SimulatedBias.cpp
 *  @brief Range bias field of each anchor and the TDoA error: docs/math/simulation.md (S12)–(S18).
 */
#include "uwb/sim/SimulatedBias.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "uwb/core/Smoothstep.h"

namespace uwb::sim {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("BiasParams: " + what);
}

bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

/// Spherical-harmonic coefficients for degrees 1..degree (index 0, the constant, stays 0), drawn with
/// variance 1/l per degree and scaled so that the pattern's RMS over the sphere is exactly rms_m (S13):
/// for orthonormal Y_lm, (1/4π) ∫ (Σ k Y)² dΩ = Σ k² / 4π.
std::vector<double> drawPattern(int degree, double rms_m, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> k(16, 0.0);
  double sum_sq = 0.0;
  for (int l = 1; l <= 3; ++l) {
    for (int m = -l; m <= l; ++m) {
      const double draw = normal(rng);  // always drawn, so the degree does not shift the random stream
      if (l > degree) continue;
      const auto idx = static_cast<std::size_t>(l * l + l + m);
      k[idx] = draw / std::sqrt(static_cast<double>(l));
      sum_sq += k[idx] * k[idx];
    }
  }
  const double scale = sum_sq > 0.0 ? rms_m * std::sqrt(4.0 * kPi / sum_sq) : 0.0;
  for (double& v : k) v *= scale;
  return k;
}

/// splitmix64: a stateless 64-bit mix, so bursts are a pure function of (anchor key, time bin).
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// Uniform in (0, 1) from 53 bits of a hash.
double unitFromHash(std::uint64_t h) { return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53; }

double evalPattern(const std::vector<double>& k, const std::array<double, 16>& Y) {
  double v = 0.0;
  for (std::size_t i = 1; i < 16; ++i) v += k[i] * Y[i];
  return v;
}

}  // namespace

void BiasParams::validate() const {
  require(finiteNonNegative(antenna_rms_m), "antenna_rms_m must be >= 0");
  require(antenna_degree >= 1 && antenna_degree <= 3, "antenna_degree must be 1, 2 or 3");
  require(finiteNonNegative(anchor_pattern_rms_m), "anchor_pattern_rms_m must be >= 0");
  require(finiteNonNegative(anchor_offset_std_m), "anchor_offset_std_m must be >= 0");
  require(finiteNonNegative(nlos_bias_m), "nlos_bias_m must be >= 0");
  require(std::isfinite(nlos_elevation_rad) && std::abs(nlos_elevation_rad) < 0.5 * kPi,
          "nlos_elevation_rad must be within ±π/2");
  require(std::isfinite(nlos_width_rad) && nlos_width_rad > 0.0, "nlos_width_rad must be positive");
  require(std::isfinite(nlos_azimuth_gain) && std::abs(nlos_azimuth_gain) <= 1.0,
          "nlos_azimuth_gain must be within [−1, 1] (the NLOS bias must stay positive)");
  require(std::isfinite(nlos_azimuth_rad), "nlos_azimuth_rad must be finite");
  require(finiteNonNegative(multipath_std_m), "multipath_std_m must be >= 0");
  require(std::isfinite(multipath_length_m) && multipath_length_m > 0.0, "multipath_length_m must be positive");
  require(multipath_features >= 1 && multipath_features <= 4096, "multipath_features must be in 1..4096");
  require(finiteNonNegative(noise_std_m), "noise_std_m must be >= 0");
  require(std::isfinite(outlier_probability) && outlier_probability >= 0.0 && outlier_probability <= 0.5,
          "outlier_probability must be in [0, 0.5]");
  require(finiteNonNegative(outlier_scale_m), "outlier_scale_m must be >= 0");
  require(std::isfinite(outlier_dof) && outlier_dof > 0.0, "outlier_dof must be positive");
  require(std::isfinite(outlier_max_m) && outlier_max_m > 0.0, "outlier_max_m must be positive");
  require(std::isfinite(burst_probability) && burst_probability >= 0.0 && burst_probability <= 0.5,
          "burst_probability must be in [0, 0.5]");
  require(std::isfinite(burst_length_s) && burst_length_s > 0.0, "burst_length_s must be positive");
  require(finiteNonNegative(burst_scale_m), "burst_scale_m must be >= 0");
  require(std::isfinite(ground_low_anchor_z_m), "ground_low_anchor_z_m must be finite");
  require(std::isfinite(ground_low_min_m) && std::isfinite(ground_low_max_m) && ground_low_min_m <= ground_low_max_m,
          "ground_low_min_m <= ground_low_max_m required");
  require(finiteNonNegative(ground_high_abs_m), "ground_high_abs_m must be >= 0");
  require(finiteNonNegative(ground_noise_std_m), "ground_noise_std_m must be >= 0");
  require(std::isfinite(ground_blend_height_m) && ground_blend_height_m > 0.0,
          "ground_blend_height_m must be positive");
}

std::array<double, 16> realSphericalHarmonics(const Vec3& u) {
  // docs/math/simulation.md (S13): real orthonormal spherical harmonics, Cartesian form.
  const double x = u.x();
  const double y = u.y();
  const double z = u.z();
  const double z2 = z * z;
  return {0.28209479177387814,
          0.4886025119029199 * y,
          0.4886025119029199 * z,
          0.4886025119029199 * x,
          1.0925484305920792 * x * y,
          1.0925484305920792 * y * z,
          0.31539156525252005 * (3.0 * z2 - 1.0),
          1.0925484305920792 * x * z,
          0.5462742152960396 * (x * x - y * y),
          0.5900435899266435 * y * (3.0 * x * x - y * y),
          2.890611442640554 * x * y * z,
          0.4570457994644658 * y * (5.0 * z2 - 1.0),
          0.3731763325901154 * z * (5.0 * z2 - 3.0),
          0.4570457994644658 * x * (5.0 * z2 - 1.0),
          1.445305721320277 * z * (x * x - y * y),
          0.5900435899266435 * x * (x * x - 3.0 * y * y)};
}

SimulatedBias::SimulatedBias(const BiasParams& params, const AnchorSurvey& survey, std::mt19937_64& field_rng,
                     std::mt19937_64& flight_rng)
    : params_(params) {
  params_.validate();
  if (survey.anchors.empty()) throw std::invalid_argument("SimulatedBias: the survey has no anchors");
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  tag_coeffs_ = drawPattern(params_.antenna_degree, params_.antenna_rms_m, field_rng);
  for (const Anchor& anchor : survey.anchors) {
    AnchorTerms t;
    t.id = anchor.id;
    t.w_p = anchor.w_p;
    t.offset_m = params_.anchor_offset_std_m * normal(field_rng);
    t.pattern_coeffs = drawPattern(params_.antenna_degree, params_.anchor_pattern_rms_m, field_rng);
    // (S15) random Fourier features of a squared-exponential field with length ℓ: ω ~ N(0, I/ℓ²).
    const auto k = static_cast<std::size_t>(params_.multipath_features);
    t.mp_freq.resize(k);
    t.mp_phase.resize(k);
    for (std::size_t i = 0; i < k; ++i) {
      t.mp_freq[i] = Vec3(normal(field_rng), normal(field_rng), normal(field_rng)) / params_.multipath_length_m;
      t.mp_phase[i] = 2.0 * kPi * uniform(field_rng);
    }
    // (S18) ground range bias: low anchors far off, the others a little.
    const double g = uniform(flight_rng);
    t.ground_m = anchor.w_p.z() < params_.ground_low_anchor_z_m
                     ? params_.ground_low_min_m + (params_.ground_low_max_m - params_.ground_low_min_m) * g
                     : params_.ground_high_abs_m * (2.0 * g - 1.0);
    t.burst_key = flight_rng();
    t.burst_phase = uniform(flight_rng);
    anchors_.push_back(std::move(t));
  }
}

const SimulatedBias::AnchorTerms& SimulatedBias::terms(int id) const {
  for (const AnchorTerms& t : anchors_) {
    if (t.id == id) return t;
  }
  throw std::invalid_argument("SimulatedBias: anchor id " + std::to_string(id) + " is not in the survey");
}

double SimulatedBias::patternBias(int anchor_id, const Vec3& b_u) const {
  const AnchorTerms& t = terms(anchor_id);
  const std::array<double, 16> Y = realSphericalHarmonics(b_u);
  // (S12) c_i + h_tag(u) + h_i(u) + n(u)
  double bias = t.offset_m + evalPattern(tag_coeffs_, Y) + evalPattern(t.pattern_coeffs, Y);
  // (S14) body occlusion: positive bias when the anchor is below the rotor plane, more toward the battery.
  const double elevation = std::asin(std::clamp(b_u.z(), -1.0, 1.0));
  const double shadow = smoothstep3((params_.nlos_elevation_rad - elevation) / params_.nlos_width_rad);
  if (shadow > 0.0) {
    const double azimuth = std::atan2(b_u.y(), b_u.x());
    bias += params_.nlos_bias_m * shadow * (1.0 + params_.nlos_azimuth_gain * std::cos(azimuth - params_.nlos_azimuth_rad));
  }
  return bias;
}

double SimulatedBias::multipathBias(int anchor_id, const Vec3& w_p_tag) const {
  const AnchorTerms& t = terms(anchor_id);
  if (params_.multipath_std_m == 0.0) return 0.0;
  // (S15) m_i(p) = σ √(2/K) Σ cos(ω_k·p + φ_k)
  double sum = 0.0;
  for (std::size_t i = 0; i < t.mp_freq.size(); ++i) sum += std::cos(t.mp_freq[i].dot(w_p_tag) + t.mp_phase[i]);
  return params_.multipath_std_m * std::sqrt(2.0 / static_cast<double>(t.mp_freq.size())) * sum;
}

double SimulatedBias::burstBias(int anchor_id, double t_s) const {
  const AnchorTerms& t = terms(anchor_id);
  if (params_.burst_probability == 0.0 || params_.burst_scale_m == 0.0) return 0.0;
  // (S16b) time bin k = ⌊t / L + φ_i⌋; a burst with probability p_b; excess s_b |t₂| with the closed-form
  // Student-t (ν = 2) quantile t₂ = (2u − 1) / √(2u(1 − u)).
  const auto bin = static_cast<std::int64_t>(std::floor(t_s / params_.burst_length_s + t.burst_phase));
  const std::uint64_t h1 = splitmix64(t.burst_key ^ static_cast<std::uint64_t>(bin));
  if (unitFromHash(h1) >= params_.burst_probability) return 0.0;
  const double u = unitFromHash(splitmix64(h1));
  const double t2 = (2.0 * u - 1.0) / std::sqrt(2.0 * u * (1.0 - u));
  return std::min(params_.burst_scale_m * std::abs(t2), params_.outlier_max_m);
}

double SimulatedBias::groundBias(int anchor_id) const { return terms(anchor_id).ground_m; }

double SimulatedBias::groundWeight(double height_m) const {
  // (S18) w(h) = 1 − smoothstep(h / h_blend)
  return 1.0 - smoothstep3(height_m / params_.ground_blend_height_m);
}

TdoaErrorParts SimulatedBias::sample(double t_s, int id_a, int id_b, const Vec3& w_p_tag, const Quat& w_q_b, double height_m,
                                 std::mt19937_64& rng) const {
  TdoaErrorParts e;
  if (!params_.enabled) return e;
  const AnchorTerms& a = terms(id_a);
  const AnchorTerms& b = terms(id_b);
  const Mat3 b_R_w = w_q_b.toRotationMatrix().transpose();
  const Vec3 b_u_a = (b_R_w * (a.w_p - w_p_tag)).normalized();  // direction tag → anchor, body frame
  const Vec3 b_u_b = (b_R_w * (b.w_p - w_p_tag)).normalized();
  // (S17) TDoA error = β_B − β_A + ν + o + g
  e.pattern_m = patternBias(id_b, b_u_b) - patternBias(id_a, b_u_a);
  e.multipath_m = multipathBias(id_b, w_p_tag) - multipathBias(id_a, w_p_tag);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  // Fixed number of draws per measurement, so changing one magnitude does not reshuffle the others.
  const double n_noise = normal(rng);
  const double n_ground = normal(rng);
  const double u_outlier = uniform(rng);
  const double u_sign = uniform(rng);
  std::student_t_distribution<double> student(params_.outlier_dof);
  const double t_draw = student(rng);
  e.noise_m = params_.noise_std_m * n_noise;
  if (u_outlier < params_.outlier_probability) {
    // (S16) a delayed (NLOS) first path lengthens one range: + on B, − on A.
    const double magnitude = std::min(params_.outlier_scale_m * std::abs(t_draw), params_.outlier_max_m);
    e.outlier_m = u_sign < 0.5 ? magnitude : -magnitude;
  }
  e.outlier_m += burstBias(id_b, t_s) - burstBias(id_a, t_s);  // (S16b) a delayed path lengthens that range
  if (params_.ground_effect) {
    const double w = groundWeight(height_m);
    if (w > 0.0) e.ground_m = w * (b.ground_m - a.ground_m + params_.ground_noise_std_m * n_ground);
  }
  return e;
}

}  // namespace uwb::sim
