/** @file SvgpTrainer.h
 *  @brief Training of a whitened SVGP: k-means++ inducing points, Adam with a decaying learning rate for the
 *         hyperparameters and inducing points, natural-gradient steps for q(v) (Salimbeni et al. 2018).
 *
 *  docs/math/gp.md P21–P24, P40–P42. Deterministic for a given seed and thread count (one std::mt19937_64; a
 *  minibatch is split into as many contiguous parts as threads and their sums are added in thread order).
 */
#pragma once

#include <cstdint>
#include <functional>
#include <limits>

#include "uwb/gp/Svgp.h"

namespace uwb::gp {

/// Most threads one training may use (SvgpTrainParams::num_threads): more is refused before any is started.
inline constexpr int kMaxTrainThreads = 256;

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
  /// Threads that share each minibatch (0: one per hardware thread). Results depend on the seed and on this count
  /// (the order of the partial sums), not on scheduling.
  int num_threads = 0;  ///< at most kMaxTrainThreads
  /// After the last step, set q(v) to its optimum for the final hyperparameters on the FULL data (P41): the returned
  /// model does not depend on which minibatch came last, and its full-data ELBO is never below the last iterate's.
  bool final_full_data_q = true;
  /// After the last step, compute SvgpTrainSummary::final_elbo on the FULL data (one more pass over all of it).
  bool final_full_data_elbo = true;
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
  int batches_per_epoch = 0;
  /// ELBO per datum on the full training data of the returned model (P15 summed over all data).
  double final_elbo = std::numeric_limits<double>::quiet_NaN();
};

/// Minibatch sizes of one epoch (P40): ⌈N/B⌉ batches whose sizes differ by at most one (batch b covers positions
/// ⌊bN/n⌋ … ⌊(b+1)N/n⌋ − 1 of the epoch's permutation), so no step sees a tiny remainder batch whose natural-gradient
/// step would be scaled by N/r.
std::vector<Eigen::Index> balancedBatchSizes(Eigen::Index num_data, Eigen::Index batch_size);

/// ELBO per datum (P15) over ALL of (X, y): Σ_n ELL_n / N − KL / N, in chunks (no copy of X), on num_threads threads
/// (0: one per hardware thread).
ElboTerms fullDataElbo(const Svgp& gp, const MatX& X, const VecX& y, int num_threads = 1);

/// Sets q(v) to the ELBO's optimum for gp's current kernel, inducing points, mean and noise on all of (X, y) (P41):
/// S⁻¹ = I + σ⁻² Σ_n a_n a_nᵀ, m = S σ⁻² Σ_n a_n (y_n − c). Chunks, threads as fullDataElbo.
void setOptimalVariational(Svgp& gp, const MatX& X, const VecX& y, int num_threads = 1);

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
