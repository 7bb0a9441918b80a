/** @file SvgpTrainer.h
 *  @brief Training of a whitened SVGP: k-means++ inducing points, Adam with a decaying learning rate for the
 *         hyperparameters and inducing points, natural-gradient steps for q(v) (Salimbeni et al. 2018).
 *
 *  docs/math/gp.md P21–P24. Deterministic for a given seed (one std::mt19937_64, no threads).
 */
#pragma once

#include <cstdint>
#include <functional>
#include <limits>

#include "uwb/gp/Svgp.h"

namespace uwb::gp {

struct SvgpTrainParams {
  int epochs = 30;                 ///< passes over the training data
  int batch_size = 1024;           ///< minibatch size B (clipped to N)
  std::uint64_t seed = 1;          ///< shuffling and k-means++ seed
  double lr = 0.01;                ///< Adam step for log-hyperparameters, log-noise and the mean
  double lr_inducing = 0.01;       ///< Adam step for the inducing points (transformed input units)
  double lr_final_fraction = 0.1;  ///< learning rates decay exponentially to this fraction at the last step
  double natgrad_step = 0.2;       ///< γ of the natural-gradient step on q(v); ≤ 0: optimize m, L with Adam
  double lr_variational = 0.01;    ///< Adam step for m, L when natgrad_step ≤ 0
  bool train_inducing = true;      ///< optimize Z
  bool train_hyperparameters = true;
  double min_noise_variance = 1e-6;  ///< floor on σ_n² [output units²]
  ElboMode mode = ElboMode::kFast;
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// One line of the progress report.
struct EpochReport {
  int epoch = 0;            ///< 1-based
  int epochs = 0;
  double elbo = 0.0;        ///< mean minibatch ELBO per datum over the epoch
  double val_rmse = std::numeric_limits<double>::quiet_NaN();  ///< RMSE of (y_val − mean) if validation given
  double elapsed_s = 0.0;
};

struct SvgpTrainSummary {
  std::vector<EpochReport> history;
  double seconds = 0.0;
  int steps = 0;
};

/// k-means++ seeding (Arthur & Vassilvitskii 2007) then `lloyd_iterations` Lloyd steps; returns M×D centers.
/// At most `max_points` rows (a seeded random subset) are used. Throws when X has fewer than M distinct rows.
MatX kmeansPlusPlus(const MatX& X, int M, std::uint64_t seed, int lloyd_iterations = 10, int max_points = 20000);

enum class InputNormalization { kNone, kStandardize };

/// A fresh SVGP for data (X, y): Z by k-means++ (in the transformed space), c = mean(y), σ² of every term and
/// σ_n² set from var(y); m = 0, L = I. P21.
Svgp initSvgp(Kernel kernel, const MatX& X, const VecX& y, int num_inducing, std::uint64_t seed,
              InputNormalization normalization = InputNormalization::kNone);

/// Optimizes gp in place on (X, y). Optional validation set; on_epoch is called after every epoch.
SvgpTrainSummary trainSvgp(Svgp& gp, const MatX& X, const VecX& y, const SvgpTrainParams& params,
                           const MatX* X_val = nullptr, const VecX* y_val = nullptr,
                           const std::function<void(const EpochReport&)>& on_epoch = {});

/// Natural parameters of q(v): Λ = S⁻¹, h = S⁻¹ m (kept across steps by the trainer).
struct NaturalParams {
  MatX Lambda;
  VecX h;
  static NaturalParams fromSvgp(const Svgp& gp);
};

/// One natural-gradient step on q(v) for a Gaussian likelihood from a batch's A Aᵀ and A(y − c) (P23).
void naturalGradientStep(Svgp& gp, const MatX& AAt, const VecX& A_y_centered, double batch_size, double num_data,
                         double step);
/// The same, updating cached natural parameters `nat` (which must describe gp's current q).
void naturalGradientStep(Svgp& gp, NaturalParams& nat, const MatX& AAt, const VecX& A_y_centered, double batch_size,
                         double num_data, double step);

/// Adam (Kingma & Ba 2015) on a flat vector (P22).
class Adam {
 public:
  explicit Adam(Eigen::Index n, double beta1 = 0.9, double beta2 = 0.999, double eps = 1e-8);
  /// x ← x + lr · m̂ / (√v̂ + ε) for gradient ASCENT direction g (we maximize the ELBO); lr may vary per entry.
  void ascend(VecX& x, const VecX& g, const VecX& lr);

 private:
  VecX m_, v_;
  double b1_, b2_, eps_;
  long t_ = 0;
};

}  // namespace uwb::gp
