/** @file Svgp.cpp
 *  @brief Whitened SVGP: ELBO, analytic gradients (reverse mode by hand), predictions (docs/math/gp.md P11–P20).
 */
#include "uwb/gp/Svgp.h"

#include "uwb/gp/PredictTile.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <exception>
#include <memory>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace uwb::gp {

namespace {

constexpr double kLog2Pi = 1.83787706640934548356065947281123;

MatX choleskyOrThrow(const MatX& K, const char* what) {
  Eigen::LLT<MatX> llt(K);
  if (llt.info() != Eigen::Success) {
    throw std::runtime_error(std::string(what) + ": matrix is not positive definite (Cholesky failed)");
  }
  return llt.matrixL();
}

/// Φ(X): lower triangle with the diagonal halved (Murray 2016; P18).
MatX phi(const MatX& X) {
  MatX P = X.triangularView<Eigen::Lower>();
  P.diagonal() *= 0.5;
  return P;
}

template <class T>
nlohmann::json matToJson(const T& M) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    std::vector<double> r(static_cast<std::size_t>(M.cols()));
    for (Eigen::Index j = 0; j < M.cols(); ++j) r[static_cast<std::size_t>(j)] = M(i, j);
    rows.push_back(r);
  }
  return rows;
}

MatX matFromJson(const nlohmann::json& j, const char* what) {
  if (!j.is_array() || j.empty()) throw std::invalid_argument(std::string(what) + ": expected a non-empty matrix");
  const std::size_t rows = j.size(), cols = j[0].size();
  MatX M(rows, cols);
  for (std::size_t i = 0; i < rows; ++i) {
    if (!j[i].is_array() || j[i].size() != cols)
      throw std::invalid_argument(std::string(what) + ": ragged matrix (row " + std::to_string(i) + ")");
    for (std::size_t k = 0; k < cols; ++k) M(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = j[i][k].get<double>();
  }
  return M;
}

VecX vecFromJson(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const VecX>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

double relativeError(const MatX& a, const MatX& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return std::numeric_limits<double>::infinity();
  const double denom = b.cwiseAbs().maxCoeff();
  const double num = (a - b).cwiseAbs().maxCoeff();
  return denom > 0 ? num / denom : num;
}

Svgp::Svgp(Kernel kernel, MatX Z, double jitter) : kernel_(std::move(kernel)), jitter_(jitter) {
  setInducing(Z);
  m_ = VecX::Zero(Z_.rows());
  L_ = MatX::Identity(Z_.rows(), Z_.rows());
}

void Svgp::setInducing(const MatX& Z) {
  if (Z.rows() < 1) throw std::invalid_argument("SVGP: need at least one inducing point");
  if (Z.cols() < kernel_.inputDim())
    throw std::invalid_argument("SVGP: inducing points have " + std::to_string(Z.cols()) + " columns, kernel reads " +
                                std::to_string(kernel_.inputDim()));
  if (Z_.size() > 0 && Z.rows() != Z_.rows()) throw std::invalid_argument("SVGP: number of inducing points changed");
  Z_ = Z;
}

void Svgp::setVariational(const VecX& m, const MatX& L) {
  if (m.size() != Z_.rows() || L.rows() != Z_.rows() || L.cols() != Z_.rows())
    throw std::invalid_argument("SVGP: variational parameters must be M=" + std::to_string(Z_.rows()) + " sized");
  if ((L.diagonal().array() == 0.0).any()) throw std::invalid_argument("SVGP: L has a zero on its diagonal");
  m_ = m;
  L_ = L.triangularView<Eigen::Lower>();
}

void Svgp::setNoiseVariance(double s2) {
  if (!(s2 > 0.0) || !std::isfinite(s2)) throw std::invalid_argument("SVGP: noise variance must be positive");
  noise_ = s2;
}

void Svgp::setInputTransform(const VecX& shift, const VecX& scale) {
  if (shift.size() != scale.size()) throw std::invalid_argument("SVGP: input shift and scale differ in size");
  if (scale.size() > 0 && !(scale.array() > 0.0).all()) throw std::invalid_argument("SVGP: input scale must be > 0");
  shift_ = shift;
  scale_ = scale;
}

MatX Svgp::transformInputs(const MatX& X) const {
  if (shift_.size() == 0) return X;
  if (X.cols() != shift_.size()) throw std::invalid_argument("SVGP: input has the wrong number of columns");
  return ((X.rowwise() - shift_.transpose()).array().rowwise() / scale_.transpose().array()).matrix();
}

std::map<std::string, Parameter> Svgp::params() const {
  auto p = kernel_.params();
  p["likelihood.noise"] = {noise_, true};
  p["mean.constant"] = {c_, true};
  return p;
}

void Svgp::setParam(const std::string& name, double value) {
  if (name == "likelihood.noise")
    setNoiseVariance(value);
  else if (name == "mean.constant")
    c_ = value;
  else
    kernel_.setParam(name, value);
}

double Svgp::kl() const {
  // P14: KL = ½ [tr S + mᵀm − M − Σ log L_ii²]
  const double M = static_cast<double>(m_.size());
  return 0.5 * (L_.squaredNorm() + m_.squaredNorm() - M - L_.diagonal().array().square().log().sum());
}

namespace {

/// The batch's latent moments before the constant mean and k + ε are added (P12–P13), and the products of either
/// mode that the reverse pass reuses.
struct ElboForward {
  VecX mean_f, var_f;  ///< aᵀm and aᵀ(S − I)a per datum
  MatX A, C;           ///< kExact: A = Lz⁻¹Kzx, C = (S − I)A
  VecX alpha;          ///< kFast: Lz⁻ᵀ m
  MatX WK;             ///< kFast: W Kzx, W = Lz⁻ᵀ (S − I) Lz⁻¹
  MatX T1;             ///< kFast: Lz⁻ᵀ (S − I), reused by the reverse pass (P17)
};

// P12–P13: mean_f = c + aᵀm, var_f = k + ε + aᵀ(S − I)a (the last two terms here)
ElboForward latentMoments(ElboMode mode, const MatX& Lz, const MatX& Kzx, const MatX& SmI, const VecX& m) {
  const auto LzT = Lz.triangularView<Eigen::Lower>();
  const Eigen::Index B = Kzx.cols();
  ElboForward f;
  f.mean_f.resize(B);
  f.var_f.resize(B);
  if (mode == ElboMode::kExact) {
    f.A = LzT.solve(Kzx);
    f.C.noalias() = SmI * f.A;
    f.mean_f.noalias() = f.A.transpose() * m;
    f.var_f = (f.A.array() * f.C.array()).colwise().sum().transpose();
  } else {
    f.alpha = LzT.transpose().solve(m);
    f.T1 = LzT.transpose().solve(SmI);                           // Lz⁻ᵀ (S − I)
    MatX W = LzT.transpose().solve(f.T1.transpose()).transpose();  // Lz⁻ᵀ (S − I) Lz⁻¹
    W = 0.5 * (W + W.transpose()).eval();
    f.WK.noalias() = W * Kzx;
    f.mean_f.noalias() = Kzx.transpose() * f.alpha;
    f.var_f = (Kzx.array() * f.WK.array()).colwise().sum().transpose();
  }
  return f;
}

/// Reverse pass over the batch: A Aᵀ and A r (P16), K̄zx = ∂ELBO/∂Kzx, and K̄zz = ∂ELBO/∂Kzz through the Cholesky
/// factor Lz (P17–P18).
struct ElboAdjoints {
  MatX AAt;
  VecX Ar;
  MatX Kbar_zx;
  MatX Kbar_zz;
};

ElboAdjoints elboAdjoints(ElboMode mode, const MatX& Lz, const MatX& Kzx, const MatX& SmI, const ElboForward& f,
                          const VecX& m, const VecX& r, double beta) {
  const auto LzT = Lz.triangularView<Eigen::Lower>();
  const Eigen::Index M = Lz.rows();
  ElboAdjoints out;
  MatX& AAt = out.AAt;
  VecX& Ar = out.Ar;
  AAt = MatX::Zero(M, M);
  if (mode == ElboMode::kExact) {
    AAt.selfadjointView<Eigen::Lower>().rankUpdate(f.A);
    AAt = AAt.selfadjointView<Eigen::Lower>();
    Ar.noalias() = f.A * r;
    // Ā = β (m rᵀ − (S − I) A);  K̄zx = Lz⁻ᵀ Ā
    MatX Abar = -beta * f.C;
    Abar.noalias() += (beta * m) * r.transpose();
    out.Kbar_zx = LzT.transpose().solve(Abar);
  } else {
    MatX KKt = MatX::Zero(M, M);
    KKt.selfadjointView<Eigen::Lower>().rankUpdate(Kzx);
    KKt = KKt.selfadjointView<Eigen::Lower>();
    AAt = LzT.solve(LzT.solve(KKt).transpose());  // Lz⁻¹ Kzx Kxz Lz⁻ᵀ
    AAt = 0.5 * (AAt + AAt.transpose()).eval();
    Ar = LzT.solve(Kzx * r);
    // K̄zx = β (α rᵀ − W Kzx)
    out.Kbar_zx = -beta * f.WK;
    out.Kbar_zx.noalias() += (beta * f.alpha) * r.transpose();
  }

  // P17: ∂/∂Lz = tril(−K̄zx Aᵀ) = tril(−Lz⁻ᵀ Ā Aᵀ),  Ā Aᵀ = β (m (Ar)ᵀ − (S − I) A Aᵀ)
  MatX Lzbar;
  if (mode == ElboMode::kExact) {
    MatX AbarAt = -beta * (SmI * AAt);
    AbarAt.noalias() += (beta * m) * Ar.transpose();
    Lzbar = (-LzT.transpose().solve(AbarAt)).triangularView<Eigen::Lower>();
  } else {
    // Lz⁻ᵀ Ā Aᵀ = β (α (Ar)ᵀ − T1 A Aᵀ): one GEMM with the cached T1 instead of a GEMM and a triangular solve
    MatX LzAbarAt(M, M);
    LzAbarAt.noalias() = (-beta) * f.T1 * AAt;
    LzAbarAt.noalias() += (beta * f.alpha) * Ar.transpose();
    Lzbar = (-LzAbarAt).triangularView<Eigen::Lower>();
  }
  // P18: Cholesky backward: K̄zz = ½ Lz⁻ᵀ (P + Pᵀ) Lz⁻¹, P = Φ(Lzᵀ L̄z)
  const MatX P = phi(Lz.transpose().triangularView<Eigen::Upper>() * Lzbar);
  const MatX Ps = P + P.transpose();
  out.Kbar_zz = 0.5 * LzT.transpose().solve(LzT.transpose().solve(Ps).transpose());
  out.Kbar_zz = 0.5 * (out.Kbar_zz + out.Kbar_zz.transpose()).eval();
  return out;
}

}  // namespace

ElboTerms Svgp::elbo(const MatX& X_raw, const VecX& y, double num_data, SvgpGradient* grad, ElboMode mode) const {
  if (X_raw.rows() != y.size() || X_raw.rows() == 0) throw std::invalid_argument("SVGP elbo: X and y mismatch or empty");
  if (!(num_data > 0)) throw std::invalid_argument("SVGP elbo: num_data must be positive");
  const MatX X = transformInputs(X_raw);
  const Eigen::Index M = Z_.rows(), B = X.rows();
  const double s = noise_, Bd = static_cast<double>(B);
  const bool need_grad = grad != nullptr;

  // P11: Kzz = K(Z,Z) + εI = Lz Lzᵀ
  std::vector<MatX> zz_blocks, zx_blocks;
  MatX Kzz = kernel_.cross(Z_, Z_, need_grad ? &zz_blocks : nullptr);
  Kzz.diagonal().array() += jitter_;
  const MatX Lz = choleskyOrThrow(Kzz, "SVGP Kzz");
  const MatX Kzx = kernel_.cross(Z_, X, need_grad ? &zx_blocks : nullptr);
  const double kdiag = kernel_.diagValue();
  const MatX SmI = [&] {
    MatX S = L_.triangularView<Eigen::Lower>() * L_.transpose();
    S.diagonal().array() -= 1.0;
    return S;
  }();

  // P12–P13: mean_f = c + aᵀm, var_f = k + ε + aᵀ(S − I)a
  ElboForward fwd = latentMoments(mode, Lz, Kzx, SmI, m_);
  VecX& mean_f = fwd.mean_f;
  VecX& var_f = fwd.var_f;
  mean_f.array() += c_;
  var_f.array() += kdiag + jitter_;

  // P15: ELL_n and ELBO per datum
  const VecX r = y - mean_f;
  const double sum_sq = r.squaredNorm() + var_f.sum();
  ElboTerms out;
  out.exp_log_lik_sum = -0.5 * (Bd * (kLog2Pi + std::log(s)) + sum_sq / s);
  out.exp_log_lik = out.exp_log_lik_sum / Bd;
  out.kl = kl();
  out.elbo = out.exp_log_lik - out.kl / num_data;
  if (!need_grad) return out;

  // ---- reverse pass (P16–P19; FIXTURES.md §5) ----
  const double beta = 1.0 / (s * Bd);
  SvgpGradient& g = *grad;
  g.mean = beta * r.sum();
  g.noise = (-0.5 * Bd / s + 0.5 * sum_sq / (s * s)) / Bd;
  ElboAdjoints adj = elboAdjoints(mode, Lz, Kzx, SmI, fwd, m_, r, beta);  // P16–P18

  // P16: variational parameters
  g.m = beta * adj.Ar - m_ / num_data;
  MatX Linv_diag = MatX::Zero(M, M);
  Linv_diag.diagonal() = L_.diagonal().cwiseInverse();
  const MatX AAtL = adj.AAt * L_.triangularView<Eigen::Lower>();
  g.L = (-beta * AAtL - (L_ - Linv_diag) / num_data).triangularView<Eigen::Lower>();

  // P19: kernel hyperparameters and inducing points
  g.kernel = VecX::Zero(kernel_.numParams());
  MatX gZ_zz = MatX::Zero(M, Z_.cols());
  g.Z = MatX::Zero(M, Z_.cols());
  kernel_.accumulateCrossGradient(Z_, Z_, adj.Kbar_zz, zz_blocks, g.kernel, &gZ_zz);
  kernel_.accumulateCrossGradient(Z_, X, adj.Kbar_zx, zx_blocks, g.kernel, &g.Z);
  g.Z += 2.0 * gZ_zz;
  kernel_.accumulateDiagGradient(-0.5 * beta * Bd, g.kernel);  // k̄_n = −β/2 for every n
  g.AAt = std::move(adj.AAt);
  g.Ar = std::move(adj.Ar);
  return out;
}

SvgpPrediction Svgp::predict(const MatX& X_raw) const {
  // Reference path (P13, FIXTURES.md §3): a = Lz⁻¹ k_Z(x) by triangular solves; the fixtures check it directly.
  const MatX X = transformInputs(X_raw);
  MatX Kzz = kernel_.gram(Z_);
  Kzz.diagonal().array() += jitter_;
  const MatX Lz = choleskyOrThrow(Kzz, "SVGP Kzz");
  const VecX alpha = Lz.triangularView<Eigen::Lower>().transpose().solve(m_);
  const double kdiag = kernel_.diagValue();
  SvgpPrediction p;
  const Eigen::Index N = X.rows();
  p.mean.resize(N);
  p.var_f.resize(N);
  constexpr Eigen::Index kBlock = 256;
  for (Eigen::Index start = 0; start < N; start += kBlock) {
    const Eigen::Index n = std::min(kBlock, N - start);
    const MatX Kzt = kernel_.cross(Z_, X.middleRows(start, n));
    const MatX A = Lz.triangularView<Eigen::Lower>().solve(Kzt);  // P13: a = Lz⁻¹ k_Z(x)
    const MatX LtA = L_.transpose().triangularView<Eigen::Upper>() * A;
    p.mean.segment(start, n).noalias() = Kzt.transpose() * alpha;  // aᵀm = k_Zᵀ Lz⁻ᵀ m
    p.var_f.segment(start, n) = (LtA.colwise().squaredNorm() - A.colwise().squaredNorm()).transpose();
  }
  p.mean.array() += c_;
  p.var_f.array() += kdiag + jitter_;
  p.var_y = p.var_f.array() + noise_;
  return p;
}

SvgpPredictor Svgp::predictor() const { return SvgpPredictor(*this); }

SvgpPredictor::SvgpPredictor(const Svgp& gp)
    : kernel_(gp.kernel()),
      Z_(gp.inducing()),
      c_(gp.meanConstant()),
      noise_(gp.noiseVariance()),
      jitter_(gp.jitter()),
      shift_(gp.inputShift()),
      scale_(gp.inputScale()) {
  MatX Kzz = kernel_.gram(Z_);
  Kzz.diagonal().array() += jitter_;
  const MatX Lz = choleskyOrThrow(Kzz, "SVGP Kzz");
  const auto LzT = Lz.triangularView<Eigen::Lower>().transpose();
  alpha_ = LzT.solve(gp.variationalMean());
  // P20: Q = Lz⁻ᵀ (S − I) Lz⁻¹ = G Gᵀ − Lz⁻ᵀ Lz⁻¹ with G = Lz⁻ᵀ L (no explicit S − I: less cancellation)
  const Eigen::Index M = Z_.rows();
  const MatX& L = gp.variationalCholesky();
  const MatX G = LzT.solve(L);
  const MatX Li = LzT.solve(MatX::Identity(M, M));  // Lz⁻ᵀ
  Q_ = MatX::Zero(M, M);
  Q_.selfadjointView<Eigen::Lower>().rankUpdate(G, 1.0);
  Q_.selfadjointView<Eigen::Lower>().rankUpdate(Li, -1.0);
  Q_ = Q_.selfadjointView<Eigen::Lower>();
  packQu();
  kdiag_ = kernel_.diagValue();
}

void SvgpPredictor::packQu() { qpack_ = packQuPanels(Q_); }  // P33 (gp/PredictTile.h)

namespace {

constexpr Eigen::Index kPredictBlock = 128;  ///< rows of test points per kernel block (≈ 175 kB at M = 170)

/// Runs worker() on min(num_threads, blocks) threads (0: one per hardware thread; the calling thread is one of
/// them). The workers share the rows by taking kPredictBlock-row blocks from one atomic counter, so a thread slowed
/// by other load takes fewer blocks. Every row is computed by the same operations wherever it lands (P32, P33), so
/// the result does not depend on the thread count or on which thread took which block.
template <class Worker>
void runWorkers(Eigen::Index n, int num_threads, const Worker& worker) {
  if (num_threads < 0) throw std::invalid_argument("SVGP predict: num_threads must be >= 0");
  if (num_threads == 0) num_threads = std::max(1u, std::thread::hardware_concurrency());
  const Eigen::Index blocks = (n + kPredictBlock - 1) / kPredictBlock;
  const Eigen::Index parts = std::min<Eigen::Index>(num_threads, blocks);
  if (parts <= 1) {
    worker();
    return;
  }
  std::vector<std::thread> workers;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(parts));
  for (Eigen::Index t = 1; t < parts; ++t) {
    try {
      workers.emplace_back([&, t] {
        try {
          worker();
        } catch (...) {
          errors[static_cast<std::size_t>(t)] = std::current_exception();
        }
      });
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the started ones (and this one) take all the blocks, same result
    }
  }
  try {
    worker();
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& w : workers) w.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}
}  // namespace

void SvgpPredictor::predictRows(const MatX& X_raw, std::atomic<Eigen::Index>& next_block, VecX& mean,
                                VecX* var_f) const {
  const bool tf = shift_.size() > 0;
  const Eigen::Index M = Z_.rows(), N = X_raw.rows();
  // Kernel block: rows padded to a whole number of tiles (copies of the last row, whose results are dropped),
  // column-major with the leading dimension ld, 64-byte aligned so that a tile's column is one cache line.
  MatX Xb(kPredictBlock, X_raw.cols());
  AlignedDoubles kbuf(static_cast<std::size_t>(kPredictBlock * M));
  double* kdata = kbuf.data();
  double tmean[kTilePoints], tvar[kTilePoints];
  for (Eigen::Index start = next_block++ * kPredictBlock; start < N; start = next_block++ * kPredictBlock) {
    const Eigen::Index n = std::min(kPredictBlock, N - start);
    const Eigen::Index ld = (n + kTilePoints - 1) / kTilePoints * kTilePoints;
    Xb.resize(ld, X_raw.cols());
    Xb.topRows(n) = X_raw.middleRows(start, n);
    for (Eigen::Index i = n; i < ld; ++i) Xb.row(i) = Xb.row(n - 1);
    if (tf) Xb = ((Xb.rowwise() - shift_.transpose()).array().rowwise() / scale_.transpose().array()).matrix();
    Eigen::Map<MatX> K(kdata, ld, M);
    kernel_.crossInto(Xb, Z_, K);  // P32: ld×M, columns over Z, vectorized over the block's points
    for (Eigen::Index t = 0; t < ld; t += kTilePoints) {
      tileMeanQuadForm(kdata + t, ld, M, qpack_.data(), alpha_.data(), tmean, var_f ? tvar : nullptr);  // P33
      const Eigen::Index valid = std::min(kTilePoints, n - t);
      for (Eigen::Index i = 0; i < valid; ++i) {
        mean[start + t + i] = tmean[i];
        if (var_f) (*var_f)[start + t + i] = tvar[i];
      }
    }
  }
}

SvgpPrediction SvgpPredictor::predict(const MatX& X_raw, int num_threads) const {
  if (shift_.size() > 0 && X_raw.cols() != shift_.size())
    throw std::invalid_argument("SVGP: input has the wrong number of columns");
  SvgpPrediction p;
  const Eigen::Index N = X_raw.rows();
  p.mean.resize(N);
  p.var_f.resize(N);
  std::atomic<Eigen::Index> next_block{0};
  runWorkers(N, num_threads, [&] { predictRows(X_raw, next_block, p.mean, &p.var_f); });
  p.mean.array() += c_;
  p.var_f.array() += kdiag_ + jitter_;
  p.var_y = p.var_f.array() + noise_;
  return p;
}

VecX SvgpPredictor::predictMean(const MatX& X_raw, int num_threads) const {
  if (shift_.size() > 0 && X_raw.cols() != shift_.size())
    throw std::invalid_argument("SVGP: input has the wrong number of columns");
  VecX mean(X_raw.rows());
  std::atomic<Eigen::Index> next_block{0};
  runWorkers(X_raw.rows(), num_threads, [&] { predictRows(X_raw, next_block, mean, nullptr); });
  mean.array() += c_;
  return mean;
}

void SvgpPredictor::predictOne(const Eigen::Ref<const RowVecX>& x_raw, double& mean, double& var_f) const {
  // The filter predicts at every TDoA: the input row, k and Q k live in a per-thread scratch that grows on a thread's
  // first call (or a larger model) and is reused after, so a running filter does not allocate (tests/alloc).
  thread_local std::vector<double> scratch;
  const Eigen::Index d = x_raw.size(), m = Z_.rows();
  if (scratch.size() < static_cast<std::size_t>(d + 2 * m)) scratch.resize(static_cast<std::size_t>(d + 2 * m));
  Eigen::Map<RowVecX> x(scratch.data(), d);
  Eigen::Map<VecX> k(scratch.data() + d, m), qk(scratch.data() + d + m, m);
  if (shift_.size() > 0) {
    if (d != shift_.size()) throw std::invalid_argument("SVGP: input has the wrong number of columns");
    x = (x_raw - shift_.transpose()).cwiseQuotient(scale_.transpose());
  } else {
    x = x_raw;
  }
  kernel_.crossColumn(Z_, x, k);
  mean = c_ + k.dot(alpha_);
  // P20: kᵀ Q k; Q is stored full (symmetric), so a plain GEMV vectorizes best
  qk.noalias() = Q_ * k;
  var_f = kdiag_ + jitter_ + k.dot(qk);
}

// ---------------------------------------------------------------------------------------------------------------

nlohmann::json Svgp::toJson() const {
  nlohmann::json j;
  j["format"] = "uwbtdoa-svgp";
  j["version"] = 1;
  j["kernel"] = kernel_.toJson();
  j["inducing_points"] = matToJson(Z_);
  j["variational"] = {{"m", std::vector<double>(m_.data(), m_.data() + m_.size())}, {"L", matToJson(L_)}};
  j["mean"] = {{"type", "constant"}, {"constant", c_}};
  j["likelihood"] = {{"type", "gaussian"}, {"noise", noise_}};
  j["jitter"] = jitter_;
  j["input_transform"] = {{"shift", std::vector<double>(shift_.data(), shift_.data() + shift_.size())},
                          {"scale", std::vector<double>(scale_.data(), scale_.data() + scale_.size())}};
  return j;
}

Svgp Svgp::fromJson(const nlohmann::json& j) {
  try {
    if (!j.is_object()) throw std::invalid_argument("not a JSON object");
    if (j.value("format", std::string()) != "uwbtdoa-svgp")
      throw std::invalid_argument("\"format\" is not \"uwbtdoa-svgp\"");
    // Compared as JSON numbers: get<int>() of a value like 1e300 would overflow (undefined behaviour).
    if (j.at("version") != 1) throw std::invalid_argument("unsupported SVGP model version " + j.at("version").dump() + " (expected 1)");
    Svgp gp(Kernel::fromJson(j.at("kernel")), matFromJson(j.at("inducing_points"), "inducing_points"),
            j.at("jitter").get<double>());
    const VecX m = vecFromJson(j.at("variational").at("m"));
    const MatX L = matFromJson(j.at("variational").at("L"), "variational.L");
    gp.setVariational(m, L);
    gp.setMean(j.at("mean").at("constant").get<double>());
    gp.setNoiseVariance(j.at("likelihood").at("noise").get<double>());
    if (j.contains("input_transform")) {
      gp.setInputTransform(vecFromJson(j.at("input_transform").at("shift")),
                           vecFromJson(j.at("input_transform").at("scale")));
      if (gp.shift_.size() != 0 && gp.shift_.size() != gp.Z_.cols())
        throw std::invalid_argument("input_transform size does not match the inducing points");
    }
    if (!gp.Z_.allFinite() || !gp.m_.allFinite() || !gp.L_.allFinite())
      throw std::invalid_argument("non-finite numbers in the model");
    return gp;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("SVGP model JSON: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("SVGP model JSON: ") + e.what());
  }
}

}  // namespace uwb::gp
