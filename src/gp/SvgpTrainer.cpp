/** @file SvgpTrainer.cpp
 *  @brief k-means++ initialization, Adam and natural-gradient training of the SVGP (docs/math/gp.md P21–P24).
 */
#include "uwb/gp/SvgpTrainer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>
#include <system_error>
#include <thread>

namespace uwb::gp {

namespace {

int resolveThreads(int num_threads) {
  if (num_threads < 0 || num_threads > kMaxTrainThreads) {
    throw std::invalid_argument("SVGP training: num_threads must be in [0, " + std::to_string(kMaxTrainThreads) +
                                "], got " + std::to_string(num_threads));
  }
  return num_threads == 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) : num_threads;
}

/// A fixed team of threads that runs task(t) for t = 0 … size − 1 (t = 0 on the calling thread) and waits for all.
/// Kept for the whole training so that a step does not pay for thread creation.
class ThreadTeam {
 public:
  explicit ThreadTeam(int size) : size_(std::max(1, size)), errors_(static_cast<std::size_t>(size_)) {
    try {
      for (int t = 1; t < size_; ++t) workers_.emplace_back([this, t] { loop(t); });
    } catch (const std::system_error& e) {
      // The threads already started wait on start_: stop and join them before the members are destroyed (a
      // throwing constructor runs no destructor), then report how far it got.
      const std::size_t started = workers_.size() + 1;
      stopAndJoin();
      throw std::runtime_error("SVGP training: cannot start thread " + std::to_string(started + 1) + " of " +
                               std::to_string(size_) + " (" + e.what() + "); use fewer threads");
    }
  }
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;
  ~ThreadTeam() { stopAndJoin(); }
  int size() const { return size_; }

  void run(const std::function<void(int)>& task) {
    if (size_ == 1) {
      task(0);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      task_ = &task;
      pending_ = size_ - 1;
      ++generation_;
    }
    start_.notify_all();
    try {
      task(0);
    } catch (...) {
      errors_[0] = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    task_ = nullptr;
    for (auto& e : errors_) {
      if (e) {
        const std::exception_ptr first = e;
        for (auto& f : errors_) f = nullptr;
        std::rethrow_exception(first);
      }
    }
  }

 private:
  void stopAndJoin() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_.notify_all();
    for (auto& w : workers_) w.join();
    workers_.clear();
  }

  void loop(int t) {
    std::uint64_t seen = 0;
    for (;;) {
      const std::function<void(int)>* task = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        task = task_;
      }
      try {
        (*task)(t);
      } catch (...) {
        errors_[static_cast<std::size_t>(t)] = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (--pending_ == 0) done_.notify_one();
      }
    }
  }

  int size_;
  std::vector<std::exception_ptr> errors_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::function<void(int)>* task_ = nullptr;
  int pending_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

/// Rows [begin, end) of part t when n rows are cut into `parts` contiguous parts of sizes differing by ≤ 1.
std::pair<Eigen::Index, Eigen::Index> partRange(Eigen::Index n, int parts, int t) {
  return {n * t / parts, n * (t + 1) / parts};
}

constexpr Eigen::Index kFullDataChunk = 4096;  ///< rows per chunk of the full-data passes (P41)

/// Runs chunk(begin, end, t) over consecutive kFullDataChunk-row chunks of n rows; thread t takes the chunks
/// t, t + T, t + 2T, … so that every thread's partial sums are formed in a fixed order.
void forEachChunk(ThreadTeam& team, Eigen::Index n, const std::function<void(Eigen::Index, Eigen::Index, int)>& chunk) {
  const Eigen::Index chunks = (n + kFullDataChunk - 1) / kFullDataChunk;
  team.run([&](int t) {
    for (Eigen::Index c = t; c < chunks; c += team.size())
      chunk(c * kFullDataChunk, std::min(n, (c + 1) * kFullDataChunk), t);
  });
}

/// Seeded random subset of at most max_points rows (the first max_points of a shuffled index list).
MatX seededSubset(const MatX& X_all, int max_points, std::mt19937_64& rng) {
  if (X_all.rows() <= max_points) return X_all;
  std::vector<Eigen::Index> idx(static_cast<std::size_t>(X_all.rows()));
  std::iota(idx.begin(), idx.end(), 0);
  std::shuffle(idx.begin(), idx.end(), rng);
  MatX X(max_points, X_all.cols());
  for (int i = 0; i < max_points; ++i) X.row(i) = X_all.row(idx[static_cast<std::size_t>(i)]);
  return X;
}

/// k-means++ seeding and Lloyd iterations on all rows of X, drawing from rng.
MatX kmeansOnRows(const MatX& X, int M, std::mt19937_64& rng, int lloyd_iterations);

}  // namespace

void SvgpTrainParams::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("SvgpTrainParams: " + what); };
  if (epochs < 1) bad("epochs must be ≥ 1");
  if (batch_size < 1) bad("batch_size must be ≥ 1");
  if (!(lr >= 0) || !(lr_inducing >= 0) || !(lr_variational >= 0)) bad("learning rates must be ≥ 0");
  if (!(lr_final_fraction > 0) || lr_final_fraction > 1) bad("lr_final_fraction must be in (0, 1]");
  if (natgrad_step > 1) bad("natgrad_step must be ≤ 1");
  if (num_threads < 0 || num_threads > kMaxTrainThreads)
    bad("num_threads must be in [0, " + std::to_string(kMaxTrainThreads) + "] (0: one per hardware thread), got " +
        std::to_string(num_threads));
  if (!(min_noise_variance > 0)) bad("min_noise_variance must be > 0");
}

// ---------------------------------------------------------------------------------------------------------------

MatX kmeansPlusPlus(const MatX& X_all, int M, std::uint64_t seed, int lloyd_iterations, int max_points) {
  if (M < 1) throw std::invalid_argument("k-means++: need at least one center");
  std::mt19937_64 rng(seed);
  return kmeansOnRows(seededSubset(X_all, max_points, rng), M, rng, lloyd_iterations);
}

namespace {

MatX kmeansOnRows(const MatX& X, int M, std::mt19937_64& rng, int lloyd_iterations) {
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

}  // namespace

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
  // k-means++ on a seeded subset (the same rows kmeansPlusPlus would pick), transformed after subsetting: no copy of
  // the whole X is made.
  if (num_inducing < 1) throw std::invalid_argument("k-means++: need at least one center");
  std::mt19937_64 rng(seed);
  Svgp gp(kernel, kmeansOnRows(probe.transformInputs(seededSubset(X, 20000, rng)), num_inducing, rng, 10));
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

std::vector<Eigen::Index> balancedBatchSizes(Eigen::Index num_data, Eigen::Index batch_size) {
  if (num_data < 1 || batch_size < 1) throw std::invalid_argument("balancedBatchSizes: need N ≥ 1 and B ≥ 1");
  // P40: n = ⌈N/B⌉ batches, batch b = positions ⌊bN/n⌋ … ⌊(b+1)N/n⌋ − 1 (sizes ⌊N/n⌋ or ⌈N/n⌉, all ≤ B)
  const Eigen::Index n = (num_data + batch_size - 1) / batch_size;
  std::vector<Eigen::Index> sizes(static_cast<std::size_t>(n));
  for (Eigen::Index b = 0; b < n; ++b) sizes[static_cast<std::size_t>(b)] = num_data * (b + 1) / n - num_data * b / n;
  return sizes;
}

namespace {

ElboTerms fullDataElboOn(ThreadTeam& team, const Svgp& gp, const MatX& X, const VecX& y) {
  // P15 over all data: Σ_n ELL_n from chunks (each chunk's exp_log_lik_sum), then − KL; per datum.
  const Eigen::Index N = X.rows();
  std::vector<double> ell(static_cast<std::size_t>(team.size()), 0.0);
  forEachChunk(team, N, [&](Eigen::Index begin, Eigen::Index end, int t) {
    const ElboTerms e = gp.elbo(X.middleRows(begin, end - begin), y.segment(begin, end - begin),
                                static_cast<double>(N), nullptr, ElboMode::kExact);
    ell[static_cast<std::size_t>(t)] += e.exp_log_lik_sum;
  });
  ElboTerms out;
  for (double v : ell) out.exp_log_lik_sum += v;
  out.exp_log_lik = out.exp_log_lik_sum / static_cast<double>(N);
  out.kl = gp.kl();
  out.elbo = out.exp_log_lik - out.kl / static_cast<double>(N);
  return out;
}

void setOptimalVariationalOn(ThreadTeam& team, Svgp& gp, const MatX& X, const VecX& y) {
  // P41: Σ k_Z(x_n) k_Z(x_n)ᵀ and Σ k_Z(x_n)(y_n − c) over chunks, then A Aᵀ = Lz⁻¹ (Σ k kᵀ) Lz⁻ᵀ once.
  const Eigen::Index M = gp.numInducing(), N = X.rows();
  std::vector<MatX> KKt(static_cast<std::size_t>(team.size()), MatX::Zero(M, M));
  std::vector<VecX> Ky(static_cast<std::size_t>(team.size()), VecX::Zero(M));
  forEachChunk(team, N, [&](Eigen::Index begin, Eigen::Index end, int t) {
    const MatX Xt = gp.transformInputs(X.middleRows(begin, end - begin));
    const MatX Kzx = gp.kernel().cross(gp.inducing(), Xt);
    KKt[static_cast<std::size_t>(t)].selfadjointView<Eigen::Lower>().rankUpdate(Kzx);
    Ky[static_cast<std::size_t>(t)].noalias() +=
        Kzx * (y.segment(begin, end - begin).array() - gp.meanConstant()).matrix();
  });
  MatX KKt_sum = MatX::Zero(M, M);
  VecX Ky_sum = VecX::Zero(M);
  for (std::size_t t = 0; t < KKt.size(); ++t) {
    KKt_sum += KKt[t];
    Ky_sum += Ky[t];
  }
  KKt_sum = KKt_sum.selfadjointView<Eigen::Lower>();
  MatX Kzz = gp.kernel().gram(gp.inducing());
  Kzz.diagonal().array() += gp.jitter();
  const Eigen::LLT<MatX> lz(Kzz);
  if (lz.info() != Eigen::Success) throw std::runtime_error("optimal q(v): Kzz is not positive definite");
  const auto Lz = lz.matrixL();
  MatX AAt = Lz.solve(Lz.solve(KKt_sum).transpose());
  AAt = 0.5 * (AAt + AAt.transpose()).eval();
  const VecX Ay = Lz.solve(Ky_sum);
  // The natural-gradient step with γ = 1 and the whole data as the batch (B = N) lands on the optimum (P23, P41).
  NaturalParams nat = NaturalParams::fromSvgp(gp);
  naturalGradientStep(gp, nat, AAt, Ay, static_cast<double>(N), static_cast<double>(N), 1.0);
}

}  // namespace

ElboTerms fullDataElbo(const Svgp& gp, const MatX& X, const VecX& y, int num_threads) {
  if (X.rows() != y.size() || X.rows() == 0) throw std::invalid_argument("fullDataElbo: X and y mismatch or empty");
  ThreadTeam team(resolveThreads(num_threads));
  return fullDataElboOn(team, gp, X, y);
}

void setOptimalVariational(Svgp& gp, const MatX& X, const VecX& y, int num_threads) {
  if (X.rows() != y.size() || X.rows() == 0) throw std::invalid_argument("setOptimalVariational: X and y mismatch or empty");
  ThreadTeam team(resolveThreads(num_threads));
  setOptimalVariationalOn(team, gp, X, y);
}

namespace {

/// The flat optimizer vector: [log θ (P) | log σ_n² | c | Z (M·D) | m (M) | L (M·M)] (P24); m and L only without
/// natural-gradient steps (they own q(u) then).
struct OptimizerLayout {
  OptimizerLayout(const Svgp& gp, Eigen::Index num_dims, bool use_natgrad)
      : P(gp.kernel().numParams()), M(gp.numInducing()), D(num_dims), natgrad(use_natgrad) {}
  int P;
  Eigen::Index M, D;
  bool natgrad;
  Eigen::Index oZ = P + 2, om = oZ + M * D, oL = om + M, n = natgrad ? om : oL + M * M;
};

/// Base learning rate of every coordinate (0 for a frozen one).
VecX learningRates(const OptimizerLayout& o, const Svgp& gp, const SvgpTrainParams& params) {
  const int P = o.P;
  const Eigen::Index M = o.M, oL = o.oL;
  VecX lr_base = VecX::Zero(o.n);
  for (int i = 0; i < P; ++i)
    lr_base[i] = (params.train_hyperparameters && gp.kernel().trainable()[static_cast<std::size_t>(i)]) ? params.lr : 0.0;
  lr_base[P] = params.train_hyperparameters ? params.lr : 0.0;
  lr_base[P + 1] = params.lr;
  lr_base.segment(o.oZ, M * o.D).setConstant(params.train_inducing ? params.lr_inducing : 0.0);
  if (!o.natgrad) {
    lr_base.segment(o.om, M).setConstant(params.lr_variational);
    for (Eigen::Index j = 0; j < M; ++j)
      for (Eigen::Index i = j; i < M; ++i) lr_base[oL + j * M + i] = params.lr_variational;  // lower triangle
  }
  return lr_base;
}

/// The model's parameters into the optimizer vector x.
void packParams(const OptimizerLayout& o, const Svgp& gp, VecX& x) {
  const int P = o.P;
  const Eigen::Index M = o.M;
  x.head(P) = gp.kernel().theta().array().log().matrix();
  x[P] = std::log(gp.noiseVariance());
  x[P + 1] = gp.meanConstant();
  x.segment(o.oZ, M * o.D) = Eigen::Map<const VecX>(gp.inducing().data(), M * o.D);
  if (!o.natgrad) {
    x.segment(o.om, M) = gp.variationalMean();
    x.segment(o.oL, M * M) = Eigen::Map<const VecX>(gp.variationalCholesky().data(), M * M);
  }
}

/// The optimizer vector x back into the model (noise variance floored at params.min_noise_variance).
void unpackParams(const OptimizerLayout& o, const SvgpTrainParams& params, const VecX& x, Svgp& gp) {
  const int P = o.P;
  const Eigen::Index M = o.M;
  gp.kernel().setTheta(x.head(P).array().exp().matrix());
  gp.setNoiseVariance(std::max(std::exp(x[P]), params.min_noise_variance));
  gp.setMean(x[P + 1]);
  gp.setInducing(Eigen::Map<const MatX>(x.data() + o.oZ, M, o.D));
  if (!o.natgrad) gp.setVariational(x.segment(o.om, M), Eigen::Map<const MatX>(x.data() + o.oL, M, M));
}

/// Ascent direction in the optimizer coordinates (log-space chain rule for positive parameters).
void gradientVector(const OptimizerLayout& o, const SvgpGradient& g, const Svgp& gp, VecX& grad) {
  const int P = o.P;
  const Eigen::Index M = o.M;
  grad.head(P) = g.kernel.cwiseProduct(gp.kernel().theta());
  grad[P] = g.noise * gp.noiseVariance();
  grad[P + 1] = g.mean;
  grad.segment(o.oZ, M * o.D) = Eigen::Map<const VecX>(g.Z.data(), M * o.D);
  if (!o.natgrad) {
    grad.segment(o.om, M) = g.m;
    grad.segment(o.oL, M * M) = Eigen::Map<const VecX>(g.L.data(), M * M);
  }
}

/// Per thread: its contiguous part of the minibatch, its ELBO terms and gradient (P42).
struct BatchParts {
  explicit BatchParts(int T)
      : Xb(static_cast<std::size_t>(T)),
        yb(static_cast<std::size_t>(T)),
        gt(static_cast<std::size_t>(T)),
        et(static_cast<std::size_t>(T)),
        part_size(static_cast<std::size_t>(T)) {}
  std::vector<MatX> Xb;
  std::vector<VecX> yb;
  std::vector<SvgpGradient> gt;
  std::vector<ElboTerms> et;
  std::vector<Eigen::Index> part_size;
};

/// P42: every thread gathers and evaluates its contiguous part of the batch perm[start … start + size − 1] into w;
/// returns the number of parts used.
int evaluateBatchParts(ThreadTeam& team, const Svgp& gp, const MatX& X, const VecX& y,
                       const std::vector<Eigen::Index>& perm, Eigen::Index start, Eigen::Index size, ElboMode mode,
                       BatchParts& w) {
  const int parts = static_cast<int>(std::min<Eigen::Index>(team.size(), size));
  const Eigen::Index N = X.rows(), D = X.cols();
  team.run([&](int t) {
    const std::size_t ti = static_cast<std::size_t>(t);
    w.part_size[ti] = 0;
    if (t >= parts) return;
    const auto [begin, end] = partRange(size, parts, t);
    w.part_size[ti] = end - begin;
    w.Xb[ti].resize(end - begin, D);
    w.yb[ti].resize(end - begin);
    for (Eigen::Index i = begin; i < end; ++i) {
      const Eigen::Index src = perm[static_cast<std::size_t>(start + i)];
      w.Xb[ti].row(i - begin) = X.row(src);
      w.yb[ti][i - begin] = y[src];
    }
    w.et[ti] = gp.elbo(w.Xb[ti], w.yb[ti], static_cast<double>(N), &w.gt[ti], mode);
  });
  return parts;
}

/// P42: the batch ELBO and gradient are the size-weighted sums of the parts' per-datum values (every term is an
/// average over data or data-free), A Aᵀ and A r are plain sums. Parts are added in thread order: deterministic for a
/// given thread count. Returns the batch ELBO; g receives the gradient.
double sumBatchParts(const BatchParts& w, int parts, Eigen::Index size, bool natgrad, SvgpGradient& g) {
  const auto& gt = w.gt;
  double elbo = 0.0;
  for (int t = 0; t < parts; ++t) {
    const std::size_t ti = static_cast<std::size_t>(t);
    const double wt = static_cast<double>(w.part_size[ti]) / static_cast<double>(size);
    elbo += wt * w.et[ti].elbo;
    if (t == 0) {
      g.kernel = wt * gt[0].kernel;
      g.noise = wt * gt[0].noise;
      g.mean = wt * gt[0].mean;
      g.Z = wt * gt[0].Z;
      g.AAt = gt[0].AAt;
      g.Ar = gt[0].Ar;
      if (!natgrad) {
        g.m = wt * gt[0].m;
        g.L = wt * gt[0].L;
      }
    } else {
      g.kernel += wt * gt[ti].kernel;
      g.noise += wt * gt[ti].noise;
      g.mean += wt * gt[ti].mean;
      g.Z += wt * gt[ti].Z;
      g.AAt += gt[ti].AAt;
      g.Ar += gt[ti].Ar;
      if (!natgrad) {
        g.m += wt * gt[ti].m;
        g.L += wt * gt[ti].L;
      }
    }
  }
  return elbo;
}

}  // namespace

SvgpTrainSummary trainSvgp(Svgp& gp, const MatX& X, const VecX& y, const SvgpTrainParams& params, const MatX* X_val,
                           const VecX* y_val, const std::function<void(const EpochReport&)>& on_epoch) {
  params.validate();
  if (X.rows() != y.size() || X.rows() == 0) throw std::invalid_argument("trainSvgp: X and y mismatch or empty");
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::Index N = X.rows();
  const std::vector<Eigen::Index> batch_sizes = balancedBatchSizes(N, std::min<Eigen::Index>(params.batch_size, N));
  const Eigen::Index nbatches = static_cast<Eigen::Index>(batch_sizes.size());
  const bool natgrad = params.natgrad_step > 0;
  ThreadTeam team(resolveThreads(params.num_threads));
  const int T = team.size();

  const OptimizerLayout layout(gp, X.cols(), natgrad);  // (P24)
  const VecX lr_base = learningRates(layout, gp, params);
  Adam adam(layout.n);
  VecX x(layout.n);
  packParams(layout, gp, x);

  NaturalParams nat;
  if (natgrad) nat = NaturalParams::fromSvgp(gp);
  std::mt19937_64 rng(params.seed);
  std::vector<Eigen::Index> perm(static_cast<std::size_t>(N));
  std::iota(perm.begin(), perm.end(), 0);
  const double total_steps = static_cast<double>(params.epochs * nbatches);
  SvgpTrainSummary summary;
  summary.batches_per_epoch = static_cast<int>(nbatches);
  BatchParts batch_parts(T);
  VecX grad(layout.n);
  SvgpGradient g;
  for (int epoch = 1; epoch <= params.epochs; ++epoch) {
    std::shuffle(perm.begin(), perm.end(), rng);
    double elbo_sum = 0.0;
    Eigen::Index start = 0;
    for (Eigen::Index b = 0; b < nbatches; ++b) {
      const Eigen::Index size = batch_sizes[static_cast<std::size_t>(b)];
      const int parts = evaluateBatchParts(team, gp, X, y, perm, start, size, params.mode, batch_parts);
      start += size;
      elbo_sum += sumBatchParts(batch_parts, parts, size, natgrad, g);
      if (natgrad) {
        const VecX Ay = g.Ar + g.AAt * gp.variationalMean();  // A (y − c) = A r + A Aᵀ m
        naturalGradientStep(gp, nat, g.AAt, Ay, static_cast<double>(size), static_cast<double>(N), params.natgrad_step);
      }
      gradientVector(layout, g, gp, grad);
      const double progress = static_cast<double>(summary.steps) / std::max(1.0, total_steps - 1.0);
      const double decay = std::pow(params.lr_final_fraction, progress);  // exponential schedule
      adam.ascend(x, grad, lr_base * decay);
      unpackParams(layout, params, x, gp);
      ++summary.steps;
    }
    const bool last = epoch == params.epochs;
    if (last && params.final_full_data_q) setOptimalVariationalOn(team, gp, X, y);  // P41
    EpochReport rep;
    rep.epoch = epoch;
    rep.epochs = params.epochs;
    rep.elbo = elbo_sum / static_cast<double>(nbatches);
    if (last && params.final_full_data_elbo) summary.final_elbo = fullDataElboOn(team, gp, X, y).elbo;
    if (X_val && y_val && X_val->rows() > 0) {
      const SvgpPrediction p = gp.predictor().predict(*X_val, T);
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
