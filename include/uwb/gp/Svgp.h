/** @file Svgp.h
 *  @brief Whitened sparse variational GP (Hensman, Fusi, Lawrence 2013) with a Gaussian likelihood and a
 *         constant mean: ELBO per datum, its analytic gradient w.r.t. every parameter, and predictions.
 *
 *  docs/math/gp.md P11–P20 (FIXTURES.md §3, §5). u = f(Z) − c = Lz v, Kzz = K(Z,Z) + εI = Lz Lzᵀ,
 *  q(v) = N(m, S), S = L Lᵀ, p(v) = N(0, I):
 *    mean_f(x) = c + a(x)ᵀ m,  var_f(x) = k(x,x) + ε + a(x)ᵀ (S − I) a(x),  a(x) = Lz⁻¹ k_Z(x)
 *    ELBO = (1/B) Σ_n E_q[log N(y_n | f_n, σ_n²)] − KL(q(v) ‖ p(v)) / N_data        (paper II-C, [11])
 *  Inputs are rows; an optional input transform x̃ = (x − shift) ⊘ scale is applied before the kernel (Z lives in
 *  the transformed space).
 */
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "uwb/core/Types.h"
#include "uwb/gp/Kernel.h"

namespace uwb::gp {

/// The scalar terms of the minibatch ELBO (FIXTURES.md §3).
struct ElboTerms {
  double elbo = 0.0;             ///< (1/B) Σ ELL_n − KL / N_data
  double kl = 0.0;               ///< KL(q(v) ‖ p(v)), total
  double exp_log_lik = 0.0;      ///< (1/B) Σ ELL_n
  double exp_log_lik_sum = 0.0;  ///< Σ ELL_n
};

/// ∂ELBO/∂(every parameter), in constrained values (θ, σ_n², c, Z, m, lower triangle of L).
struct SvgpGradient {
  VecX kernel;            ///< w.r.t. Kernel::theta() (positive values, not their logs)
  double noise = 0.0;     ///< w.r.t. the noise VARIANCE σ_n²
  double mean = 0.0;      ///< w.r.t. the constant mean c
  MatX Z;                 ///< M×D, w.r.t. inducing points (transformed space)
  VecX m;                 ///< M
  MatX L;                 ///< M×M, lower triangle (zeros above)
  MatX AAt;               ///< by-product: A Aᵀ of the batch (used by natural-gradient steps)
  VecX Ar;               ///< by-product: A r, r = y − mean_f (A (y − c) = A r + A Aᵀ m)
};

/// How the O(M²B) products are formed. kExact: triangular solves with A = Lz⁻¹Kzx (reference formulas,
/// FIXTURES.md §3). kFast: one GEMM with W = Lz⁻ᵀ(S − I)Lz⁻¹ and one SYRK of Kzx (P17); same maths, ~2× fewer
/// flops, slightly less accurate for badly conditioned Kzz. Training uses kFast; tests check both.
enum class ElboMode { kExact, kFast };

struct SvgpPrediction {
  VecX mean;   ///< latent (and observation) mean
  VecX var_f;  ///< latent variance (with the jitter ε, FIXTURES.md §3)
  VecX var_y;  ///< var_f + σ_n²
};

class SvgpPredictor;

class Svgp {
 public:
  static constexpr double kDefaultJitter = 1e-6;

  Svgp() = default;
  /// Inducing points Z (M×D); m = 0 and L = I (q = prior); c = 0; σ_n² = 0.1.
  Svgp(Kernel kernel, MatX Z, double jitter = kDefaultJitter);

  const Kernel& kernel() const { return kernel_; }
  Kernel& kernel() { return kernel_; }
  const MatX& inducing() const { return Z_; }
  void setInducing(const MatX& Z);
  const VecX& variationalMean() const { return m_; }
  const MatX& variationalCholesky() const { return L_; }
  /// m (M) and L (M×M; its strictly upper part is ignored, diagonal must be non-zero).
  void setVariational(const VecX& m, const MatX& L);
  double meanConstant() const { return c_; }
  void setMean(double c) { c_ = c; }
  double noiseVariance() const { return noise_; }
  void setNoiseVariance(double s2);
  double jitter() const { return jitter_; }
  int numInducing() const { return static_cast<int>(Z_.rows()); }
  int inputDim() const { return static_cast<int>(Z_.cols()); }

  /// Input transform x̃ = (x − shift) ⊘ scale (empty vectors = identity).
  void setInputTransform(const VecX& shift, const VecX& scale);
  const VecX& inputShift() const { return shift_; }
  const VecX& inputScale() const { return scale_; }
  MatX transformInputs(const MatX& X) const;

  /// Named parameters: kernel ones plus "likelihood.noise", "mean.constant".
  std::map<std::string, Parameter> params() const;
  void setParam(const std::string& name, double value);

  /// KL(q(v) ‖ p(v)) (P14).
  double kl() const;
  /// Minibatch ELBO per datum (P15) and, when grad is non-null, its gradient (P16–P19). X in raw input space.
  ElboTerms elbo(const MatX& X, const VecX& y, double num_data, SvgpGradient* grad = nullptr,
                 ElboMode mode = ElboMode::kExact) const;

  /// Predictions at raw inputs (P13).
  SvgpPrediction predict(const MatX& X) const;
  /// An immutable, precomputed predictor (Lz, Lz⁻ᵀm, ...) for fast repeated predictions.
  SvgpPredictor predictor() const;

  nlohmann::json toJson() const;
  static Svgp fromJson(const nlohmann::json& j);  ///< throws std::invalid_argument on a malformed model

 private:
  Kernel kernel_;
  MatX Z_;
  VecX m_;
  MatX L_;
  double c_ = 0.0;
  double noise_ = 0.1;
  double jitter_ = kDefaultJitter;
  VecX shift_, scale_;
};

/// Prediction only, from a fixed Svgp; immutable and thread-compatible.
/// docs/math/gp.md (P20): precomputes α = Lz⁻ᵀ m and Q = Lz⁻ᵀ (S − I) Lz⁻¹, so that
///   mean = c + Kxz α,  var_f = k(x,x) + ε + kᵀ Q_u k  (Q_u: upper triangle of Q, off-diagonal doubled)
/// The batch path evaluates the kernel block with Kernel::crossInto (P32) and forms kᵀQ_u k with a fused,
/// register-blocked kernel over 8 points at a time (P33) that never stores K Q_u. Agrees with Svgp::predict (the
/// reference triangular-solve path) to ~1e-12 relative for well-conditioned Kzz; the error grows with cond(Kzz).
class SvgpPredictor {
 public:
  explicit SvgpPredictor(const Svgp& gp);
  /// Latent mean and variance (var_f, with ε) at one raw input row; a few microseconds at M ≈ 170.
  void predictOne(const Eigen::Ref<const RowVecX>& x, double& mean, double& var_f) const;
  /// Batch prediction (P20, P32, P33). `num_threads` > 1 runs that many std::threads (0: one per hardware thread)
  /// that take blocks of rows from a shared counter; every row is computed the same way wherever it lands, so the
  /// result does not depend on the thread count. One thread is the default: callers that already run in parallel should
  /// not oversubscribe.
  SvgpPrediction predict(const MatX& X, int num_threads = 1) const;
  /// Latent mean only (no variance): O(M) per point after the kernel row, for bulk corrections.
  VecX predictMean(const MatX& X, int num_threads = 1) const;
  double noiseVariance() const { return noise_; }

 private:
  /// Blocks of kPredictBlock rows of X_raw taken from `next_block` until none is left: mean and, when var_f is
  /// non-null, the latent variance (without c, k**, ε).
  void predictRows(const MatX& X_raw, std::atomic<Eigen::Index>& next_block, VecX& mean, VecX* var_f) const;
  void packQu();  ///< fills qpack_ from Q_ (P33)

  Kernel kernel_;
  MatX Z_;     ///< transformed space
  MatX Q_;     ///< Lz⁻ᵀ (S − I) Lz⁻¹, symmetric M×M
  std::vector<double> qpack_;  ///< Q_u packed in panels of kQuPanel columns for the fused kernel (P33)
  VecX alpha_; ///< Lz⁻ᵀ m
  double c_ = 0.0, noise_ = 0.0, jitter_ = 0.0, kdiag_ = 0.0;
  VecX shift_, scale_;
};

/// max_i |a_i − b_i| / max_i |b_i| (FIXTURES.md §6).
double relativeError(const MatX& a, const MatX& b);

}  // namespace uwb::gp
