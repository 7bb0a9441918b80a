/** @file SvgpTrainer.cpp
 *  @brief k-means++ initialization, Adam and natural-gradient training of the SVGP (docs/math/gp.md P21–P24).
 */
#include "uwb/gp/SvgpTrainer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

namespace uwb::gp {

void SvgpTrainParams::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("SvgpTrainParams: " + what); };
  if (epochs < 1) bad("epochs must be ≥ 1");
  if (batch_size < 1) bad("batch_size must be ≥ 1");
  if (!(lr >= 0) || !(lr_inducing >= 0) || !(lr_variational >= 0)) bad("learning rates must be ≥ 0");
  if (!(lr_final_fraction > 0) || lr_final_fraction > 1) bad("lr_final_fraction must be in (0, 1]");
  if (natgrad_step > 1) bad("natgrad_step must be ≤ 1");
  if (!(min_noise_variance > 0)) bad("min_noise_variance must be > 0");
}

// ---------------------------------------------------------------------------------------------------------------

MatX kmeansPlusPlus(const MatX& X_all, int M, std::uint64_t seed, int lloyd_iterations, int max_points) {
  if (M < 1) throw std::invalid_argument("k-means++: need at least one center");
  std::mt19937_64 rng(seed);
  MatX X = X_all;
  if (X_all.rows() > max_points) {  // seeded random subset
    std::vector<Eigen::Index> idx(static_cast<std::size_t>(X_all.rows()));
    std::iota(idx.begin(), idx.end(), 0);
    std::shuffle(idx.begin(), idx.end(), rng);
    X.resize(max_points, X_all.cols());
    for (int i = 0; i < max_points; ++i) X.row(i) = X_all.row(idx[static_cast<std::size_t>(i)]);
  }
  const Eigen::Index N = X.rows();
  if (N < M) throw std::invalid_argument("k-means++: " + std::to_string(N) + " points for " + std::to_string(M) + " centers");
  MatX C(M, X.cols());
  std::uniform_int_distribution<Eigen::Index> pick(0, N - 1);
  C.row(0) = X.row(pick(rng));
  VecX d2 = (X.rowwise() - C.row(0)).rowwise().squaredNorm();
  for (int k = 1; k < M; ++k) {
    const double total = d2.sum();
    if (!(total > 0)) throw std::invalid_argument("k-means++: fewer distinct points than the " + std::to_string(M) + " requested centers");
    std::uniform_real_distribution<double> u(0.0, total);
    double target = u(rng), acc = 0.0;
    Eigen::Index chosen = N - 1;
    for (Eigen::Index i = 0; i < N; ++i) {
      acc += d2[i];
      if (acc >= target && d2[i] > 0) {
        chosen = i;
        break;
      }
    }
    C.row(k) = X.row(chosen);
    d2 = d2.cwiseMin((X.rowwise() - C.row(k)).rowwise().squaredNorm());
  }
  // Lloyd iterations (empty clusters keep their center)
  std::vector<int> assign(static_cast<std::size_t>(N));
  for (int it = 0; it < lloyd_iterations; ++it) {
    for (Eigen::Index i = 0; i < N; ++i) {
      Eigen::Index best;
      (C.rowwise() - X.row(i)).rowwise().squaredNorm().minCoeff(&best);
      assign[static_cast<std::size_t>(i)] = static_cast<int>(best);
    }
    MatX sum = MatX::Zero(M, X.cols());
    VecX cnt = VecX::Zero(M);
    for (Eigen::Index i = 0; i < N; ++i) {
      sum.row(assign[static_cast<std::size_t>(i)]) += X.row(i);
      cnt[assign[static_cast<std::size_t>(i)]] += 1;
    }
    for (int k = 0; k < M; ++k)
      if (cnt[k] > 0) C.row(k) = sum.row(k) / cnt[k];
  }
  return C;
}

Svgp initSvgp(Kernel kernel, const MatX& X, const VecX& y, int num_inducing, std::uint64_t seed,
              InputNormalization normalization) {
  if (X.rows() != y.size() || X.rows() == 0) throw std::invalid_argument("initSvgp: X and y mismatch or empty");
  VecX shift, scale;
  if (normalization == InputNormalization::kStandardize) {
    shift = X.colwise().mean().transpose();
    scale = ((X.rowwise() - shift.transpose()).colwise().squaredNorm() / static_cast<double>(X.rows())).cwiseSqrt().transpose();
    for (Eigen::Index d = 0; d < scale.size(); ++d)
      if (!(scale[d] > 1e-12)) scale[d] = 1.0;
  }
  // P21: data-driven starting point
  const double ymean = y.mean();
  const double yvar = std::max((y.array() - ymean).square().mean(), 1e-8);
  VecX theta = kernel.theta();
  const int nterms = static_cast<int>(kernel.terms().size());
  for (const auto& term : kernel.terms()) {
    const double per_part = std::pow(0.5 * yvar / nterms, 1.0 / static_cast<double>(term.size()));
    for (int p : term) {
      const std::string prefix = "p" + std::to_string(p) + "." + toString(kernel.partType(p)) + ".";
      const std::string n = kernel.partType(p) == PartType::kLedergerber ? prefix + "t0" : prefix + "sigma2";
      kernel.setParam(n, per_part);
    }
  }
  Svgp probe(kernel, MatX::Zero(1, X.cols()));
  probe.setInputTransform(shift, scale);
  const MatX Xt = probe.transformInputs(X);
  Svgp gp(kernel, kmeansPlusPlus(Xt, num_inducing, seed));
  gp.setInputTransform(shift, scale);
  gp.setMean(ymean);
  gp.setNoiseVariance(0.5 * yvar);
  return gp;
}

// ---------------------------------------------------------------------------------------------------------------

Adam::Adam(Eigen::Index n, double beta1, double beta2, double eps)
    : m_(VecX::Zero(n)), v_(VecX::Zero(n)), b1_(beta1), b2_(beta2), eps_(eps) {}

void Adam::ascend(VecX& x, const VecX& g, const VecX& lr) {
  // P22: m ← β1 m + (1−β1) g, v ← β2 v + (1−β2) g², x ← x + lr m̂/(√v̂ + ε)
  ++t_;
  m_ = b1_ * m_ + (1.0 - b1_) * g;
  v_ = b2_ * v_ + (1.0 - b2_) * g.cwiseAbs2();
  const double c1 = 1.0 - std::pow(b1_, static_cast<double>(t_));
  const double c2 = 1.0 - std::pow(b2_, static_cast<double>(t_));
  x.array() += lr.array() * (m_.array() / c1) / ((v_.array() / c2).sqrt() + eps_);
}

NaturalParams NaturalParams::fromSvgp(const Svgp& gp) {
  const Eigen::Index M = gp.numInducing();
  const MatX Linv = gp.variationalCholesky().triangularView<Eigen::Lower>().solve(MatX::Identity(M, M));
  NaturalParams nat;
  nat.Lambda = Linv.transpose() * Linv;  // S⁻¹ = L⁻ᵀ L⁻¹
  nat.h = nat.Lambda * gp.variationalMean();
  return nat;
}

void naturalGradientStep(Svgp& gp, const MatX& AAt, const VecX& A_y_centered, double batch_size, double num_data,
                         double step) {
  NaturalParams nat = NaturalParams::fromSvgp(gp);
  naturalGradientStep(gp, nat, AAt, A_y_centered, batch_size, num_data, step);
}

void naturalGradientStep(Svgp& gp, NaturalParams& nat, const MatX& AAt, const VecX& A_y_centered, double batch_size,
                         double num_data, double step) {
  // P23: in natural parameters (Λ = S⁻¹, h = S⁻¹m) of q(v), a natural-gradient step of size γ with a Gaussian
  // likelihood is a convex combination with the batch optimum Λ* = I + (N/(Bσ²)) A Aᵀ, h* = (N/(Bσ²)) A (y − c).
  const Eigen::Index M = gp.numInducing();
  const double scale = num_data / (batch_size * gp.noiseVariance());
  nat.Lambda *= (1.0 - step);
  nat.Lambda.noalias() += (step * scale) * AAt;
  nat.Lambda.diagonal().array() += step;
  nat.Lambda = 0.5 * (nat.Lambda + nat.Lambda.transpose()).eval();
  nat.h = (1.0 - step) * nat.h + (step * scale) * A_y_centered;
  // Lower factor of S = Λ⁻¹ from one Cholesky of the reversed Λ: JΛJ = R Rᵀ ⇒ S = (J R⁻ᵀ J)(J R⁻ᵀ J)ᵀ, and
  // J R⁻ᵀ J is lower triangular with a positive diagonal.
  const MatX Lambda_rev = nat.Lambda.reverse();
  const Eigen::LLT<MatX> llt(Lambda_rev);
  if (llt.info() != Eigen::Success) throw std::runtime_error("natural-gradient step: Λ not positive definite");
  const MatX Rinv = llt.matrixL().solve(MatX::Identity(M, M));
  const MatX L = Rinv.transpose().reverse();
  const VecX m = L * (L.transpose() * nat.h);  // m = S h
  gp.setVariational(m, L);
}

SvgpTrainSummary trainSvgp(Svgp& gp, const MatX& X, const VecX& y, const SvgpTrainParams& params, const MatX* X_val,
                           const VecX* y_val, const std::function<void(const EpochReport&)>& on_epoch) {
  params.validate();
  if (X.rows() != y.size() || X.rows() == 0) throw std::invalid_argument("trainSvgp: X and y mismatch or empty");
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::Index N = X.rows(), D = X.cols(), M = gp.numInducing();
  const Eigen::Index B = std::min<Eigen::Index>(params.batch_size, N);
  const Eigen::Index nbatches = (N + B - 1) / B;
  const bool natgrad = params.natgrad_step > 0;
  const int P = gp.kernel().numParams();

  // Flat optimizer vector: [log θ (P) | log σ_n² | c | Z (M·D) | m (M) | L (M·M)]  (P24)
  const Eigen::Index oZ = P + 2, om = oZ + M * D, oL = om + M, n = natgrad ? om : oL + M * M;
  VecX lr_base = VecX::Zero(n);
  for (int i = 0; i < P; ++i)
    lr_base[i] = (params.train_hyperparameters && gp.kernel().trainable()[static_cast<std::size_t>(i)]) ? params.lr : 0.0;
  lr_base[P] = params.train_hyperparameters ? params.lr : 0.0;
  lr_base[P + 1] = params.lr;
  lr_base.segment(oZ, M * D).setConstant(params.train_inducing ? params.lr_inducing : 0.0);
  if (!natgrad) {
    lr_base.segment(om, M).setConstant(params.lr_variational);
    for (Eigen::Index j = 0; j < M; ++j)
      for (Eigen::Index i = j; i < M; ++i) lr_base[oL + j * M + i] = params.lr_variational;  // lower triangle
  }
  Adam adam(n);
  VecX x(n);
  auto pack = [&] {
    x.head(P) = gp.kernel().theta().array().log().matrix();
    x[P] = std::log(gp.noiseVariance());
    x[P + 1] = gp.meanConstant();
    x.segment(oZ, M * D) = Eigen::Map<const VecX>(gp.inducing().data(), M * D);
    if (!natgrad) {
      x.segment(om, M) = gp.variationalMean();
      x.segment(oL, M * M) = Eigen::Map<const VecX>(gp.variationalCholesky().data(), M * M);
    }
  };
  auto unpack = [&] {
    gp.kernel().setTheta(x.head(P).array().exp().matrix());
    gp.setNoiseVariance(std::max(std::exp(x[P]), params.min_noise_variance));
    gp.setMean(x[P + 1]);
    gp.setInducing(Eigen::Map<const MatX>(x.data() + oZ, M, D));
    if (!natgrad) gp.setVariational(x.segment(om, M), Eigen::Map<const MatX>(x.data() + oL, M, M));
  };
  pack();

  NaturalParams nat;
  if (natgrad) nat = NaturalParams::fromSvgp(gp);
  std::mt19937_64 rng(params.seed);
  std::vector<Eigen::Index> perm(static_cast<std::size_t>(N));
  std::iota(perm.begin(), perm.end(), 0);
  const double total_steps = static_cast<double>(params.epochs * nbatches);
  SvgpTrainSummary summary;
  MatX Xb;
  VecX yb, grad(n);
  SvgpGradient g;
  for (int epoch = 1; epoch <= params.epochs; ++epoch) {
    std::shuffle(perm.begin(), perm.end(), rng);
    double elbo_sum = 0.0;
    for (Eigen::Index b = 0; b < nbatches; ++b) {
      const Eigen::Index start = b * B, size = std::min(B, N - start);
      Xb.resize(size, X.cols());
      yb.resize(size);
      for (Eigen::Index i = 0; i < size; ++i) {
        Xb.row(i) = X.row(perm[static_cast<std::size_t>(start + i)]);
        yb[i] = y[perm[static_cast<std::size_t>(start + i)]];
      }
      const ElboTerms e = gp.elbo(Xb, yb, static_cast<double>(N), &g, params.mode);
      elbo_sum += e.elbo;
      if (natgrad) {
        const VecX Ay = g.Ar + g.AAt * gp.variationalMean();  // A (y − c) = A r + A Aᵀ m
        naturalGradientStep(gp, nat, g.AAt, Ay, static_cast<double>(size), static_cast<double>(N), params.natgrad_step);
      }
      // ascent direction in the optimizer coordinates (log-space chain rule for positive parameters)
      grad.head(P) = g.kernel.cwiseProduct(gp.kernel().theta());
      grad[P] = g.noise * gp.noiseVariance();
      grad[P + 1] = g.mean;
      grad.segment(oZ, M * D) = Eigen::Map<const VecX>(g.Z.data(), M * D);
      if (!natgrad) {
        grad.segment(om, M) = g.m;
        grad.segment(oL, M * M) = Eigen::Map<const VecX>(g.L.data(), M * M);
      }
      const double progress = static_cast<double>(summary.steps) / std::max(1.0, total_steps - 1.0);
      const double decay = std::pow(params.lr_final_fraction, progress);  // exponential schedule
      adam.ascend(x, grad, lr_base * decay);
      unpack();
      ++summary.steps;
    }
    EpochReport rep;
    rep.epoch = epoch;
    rep.epochs = params.epochs;
    rep.elbo = elbo_sum / static_cast<double>(nbatches);
    if (X_val && y_val && X_val->rows() > 0) {
      const SvgpPrediction p = gp.predictor().predict(*X_val);
      rep.val_rmse = std::sqrt((*y_val - p.mean).squaredNorm() / static_cast<double>(y_val->size()));
    }
    rep.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    summary.history.push_back(rep);
    if (on_epoch) on_epoch(rep);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace uwb::gp
