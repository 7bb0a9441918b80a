/** @file Kernel.cpp
 *  @brief Block evaluation of composite kernels and their gradients (docs/math/gp.md P1–P10; paper eq. 7–9).
 */
#include "uwb/gp/Kernel.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace uwb::gp {

namespace {

constexpr double kSqrt5 = 2.23606797749978969640917366873128;

/// The active columns of X, as an n×d matrix.
MatX activeCols(const MatX& X, const std::vector<int>& dims) {
  MatX out(X.rows(), static_cast<Eigen::Index>(dims.size()));
  for (std::size_t d = 0; d < dims.size(); ++d) out.col(static_cast<Eigen::Index>(d)) = X.col(dims[d]);
  return out;
}

/// Row norms of a n×3 matrix; throws when one is (numerically) zero: k_L is undefined at x = 0 (P4).
VecX rowNorms(const MatX& A) {
  VecX n = A.rowwise().norm();
  if (n.size() > 0 && n.minCoeff() < 1e-12) {
    throw std::invalid_argument("ledergerber kernel: input vector of zero norm (k_L is undefined at x = 0)");
  }
  return n;
}

/// The rows of A scaled to unit length, and their norms (P4: γ = xᵀx'/(n n')).
struct UnitRows {
  VecX norm;
  MatX unit;
};
UnitRows unitRows(const MatX& A) {
  UnitRows u;
  u.norm = rowNorms(A);
  u.unit = u.norm.cwiseInverse().asDiagonal() * A;
  return u;
}

// ---- The part formulas (docs/math/gp.md P1–P4), written once and used by every evaluation path ----
// (cross/partCross is the reference; crossInto and crossColumn are its batch and one-point forms and are tested
// against it: Kernel.CrossIntoEqualsCross, Kernel.CrossColumnEqualsCross; the gradients are tested against central
// differences of it.)

/// (P2) Matérn-5/2 polynomial 1 + √5ρ + 5ρ²/3, in terms of r = √5ρ: k = σ² (1 + r + r²/3) e^{−r}.
template <class R>
auto matern52Polynomial(const R& r) {
  return 1.0 + r + r.square() / 3.0;
}

/// (P1) One dimension of the periodic exponent sum, sin²(π Δ / T) / l², with c = π/T and il2 = 1/l².
template <class D>
auto periodicTerm(const D& delta, double c, double il2) {
  return il2 * (c * delta).sin().square();
}

/// (P4) Exponent of the Ledergerber kernel, −(1 − γ)/θ1 − (n − n')²/θ2, with dn = n − n'.
template <class G, class N>
auto ledergerberExponent(const G& gamma, const N& dn, double t1, double t2) {
  return -(1.0 - gamma) / t1 - dn.square() / t2;
}

// ---- e^x for the batch path: docs/math/gp.md (P32) ----
// e^x = 2^k e^r, k = round(x log₂e) (by adding 1.5·2⁵², which leaves k in the low mantissa bits), r = x − k ln2 in
// two FMA steps (fdlibm's split of ln2: k·ln2_hi is exact), e^r by a degree-11 polynomial: the Taylor series to
// degree 14 economized with Chebyshev polynomials on |r| ≤ 0.347 (≥ ln2/2), max relative error 1.3e-17 in exact
// arithmetic with these double coefficients (derivation: docs/math/gp.md P32), 2^k by writing k + 1023 into the
// exponent field. x is clamped to ≤ 709 (no overflow); x < −708 (e^x < 3.3e-308) gives 0; NaN stays NaN. The
// vector and scalar versions perform the same correctly rounded operations, so a value does not depend on which
// of them computed it.
constexpr double kLog2e = 1.4426950408889634074;
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kRoundMagic = 6755399441055744.0;  // 1.5 · 2⁵²
constexpr double kExpHi = 709.0, kExpLo = -708.0;
constexpr int kExpDegree = 11;
constexpr double kExpPoly[kExpDegree + 1] = {
    0x1.0000000000000p+0,  0x1.0000000000000p+0,  0x1.0000000000011p-1,  0x1.5555555555562p-3,
    0x1.555555554efcep-5,  0x1.111111110db07p-7,  0x1.6c16c18831258p-10, 0x1.a01a01b8250c1p-13,
    0x1.a019911e43ba2p-16, 0x1.71dde72259573p-19, 0x1.28b488d801794p-22, 0x1.af78ba40f0571p-26};

#if defined(__FMA__)
inline double fmaS(double a, double b, double c) { return std::fma(a, b, c); }
#else
inline double fmaS(double a, double b, double c) { return a * b + c; }  // portable build: no FMA instruction
#endif

/// The coefficients s·p_i of s·e^r ≈ Σ s p_i r^i (the outputscale s is folded into the polynomial).
struct ScaledExpCoefs {
  double c[kExpDegree + 1];
  explicit ScaledExpCoefs(double s) {
    for (int i = 0; i <= kExpDegree; ++i) c[i] = s * kExpPoly[i];
  }
};

/// s·e^x (P32), scalar.
inline double scaledExpScalar(double x, const ScaledExpCoefs& cf) {
  x = x > kExpHi ? kExpHi : x;
  const double kd = fmaS(x, kLog2e, kRoundMagic);
  const double k = kd - kRoundMagic;
  double r = fmaS(-k, kLn2Hi, x);
  r = fmaS(-k, kLn2Lo, r);
  double p = cf.c[kExpDegree];
  for (int i = kExpDegree - 1; i >= 0; --i) p = fmaS(p, r, cf.c[i]);
  std::uint64_t bits;
  std::memcpy(&bits, &kd, sizeof bits);
  bits = (bits + 1023u) << 52;
  double scale;
  std::memcpy(&scale, &bits, sizeof scale);
  const double e = p * scale;
  return x < kExpLo ? 0.0 : e;
}

#if defined(__AVX2__) && defined(__FMA__)
/// s·e^x (P32) for kP packets of 4 lanes, step by step in lockstep (kP independent FMA chains hide the latency of
/// the degree-13 Horner recurrence); every lane performs the operations of scaledExpScalar.
template <int kP>
__attribute__((always_inline)) inline void scaledExpPackets(__m256d* x, const ScaledExpCoefs& cf) {
  const __m256d magic = _mm256_set1_pd(kRoundMagic), hi = _mm256_set1_pd(kExpHi), log2e = _mm256_set1_pd(kLog2e),
                ln2hi = _mm256_set1_pd(kLn2Hi), ln2lo = _mm256_set1_pd(kLn2Lo);
  __m256d kd[kP], r[kP], p[kP];
  for (int u = 0; u < kP; ++u) {
    x[u] = _mm256_min_pd(hi, x[u]);  // returns x when x is NaN
    kd[u] = _mm256_fmadd_pd(x[u], log2e, magic);
    const __m256d k = _mm256_sub_pd(kd[u], magic);
    r[u] = _mm256_fnmadd_pd(k, ln2hi, x[u]);
    r[u] = _mm256_fnmadd_pd(k, ln2lo, r[u]);
    p[u] = _mm256_set1_pd(cf.c[kExpDegree]);
  }
  for (int i = kExpDegree - 1; i >= 0; --i) {
    const __m256d ci = _mm256_set1_pd(cf.c[i]);
    for (int u = 0; u < kP; ++u) p[u] = _mm256_fmadd_pd(p[u], r[u], ci);
  }
  const __m256i bias = _mm256_set1_epi64x(1023);
  const __m256d lo = _mm256_set1_pd(kExpLo);
  for (int u = 0; u < kP; ++u) {
    const __m256d scale =
        _mm256_castsi256_pd(_mm256_slli_epi64(_mm256_add_epi64(_mm256_castpd_si256(kd[u]), bias), 52));
    const __m256d tiny = _mm256_cmp_pd(x[u], lo, _CMP_LT_OQ);
    x[u] = _mm256_andnot_pd(tiny, _mm256_mul_pd(p[u], scale));
  }
}
#endif

/// v[i] = s · e^{c·v[i]} for i < n, in place (P32).
void scaledExpInPlace(double* v, Eigen::Index n, double c, double s) {
  const ScaledExpCoefs cf(s);
  Eigen::Index i = 0;
#if defined(__AVX2__) && defined(__FMA__)
  const __m256d vc = _mm256_set1_pd(c);
  for (; i + 16 <= n; i += 16) {
    __m256d x[4];
    for (int u = 0; u < 4; ++u) x[u] = _mm256_mul_pd(vc, _mm256_loadu_pd(v + i + 4 * u));
    scaledExpPackets<4>(x, cf);
    for (int u = 0; u < 4; ++u) _mm256_storeu_pd(v + i + 4 * u, x[u]);
  }
  for (; i + 4 <= n; i += 4) {
    __m256d x = _mm256_mul_pd(vc, _mm256_loadu_pd(v + i));
    scaledExpPackets<1>(&x, cf);
    _mm256_storeu_pd(v + i, x);
  }
#endif
  for (; i < n; ++i) v[i] = scaledExpScalar(c * v[i], cf);
}

/// RBF part column (P3, P32): out[i] = s2 · e^{−ρ²/2}, ρ² = Σ_d (A(i,d) − b_d)² (A, b already divided by l), in
/// one pass (the distance stays in registers). kNd > 0: number of active dims known at compile time.
template <int kNd>
void rbfColumnT(const MatX& A, const double* b, const ScaledExpCoefs& cf, double* out) {
  const Eigen::Index n = A.rows(), nd = kNd > 0 ? kNd : A.cols();
  Eigen::Index i = 0;
#if defined(__AVX2__) && defined(__FMA__)
  const __m256d mhalf = _mm256_set1_pd(-0.5);
  auto halfSqDist = [&](Eigen::Index i0) {
    __m256d diff = _mm256_sub_pd(_mm256_loadu_pd(A.data() + i0), _mm256_set1_pd(b[0]));
    __m256d r2 = _mm256_mul_pd(diff, diff);
    for (Eigen::Index d = 1; d < nd; ++d) {
      diff = _mm256_sub_pd(_mm256_loadu_pd(A.data() + d * n + i0), _mm256_set1_pd(b[d]));
      r2 = _mm256_fmadd_pd(diff, diff, r2);
    }
    return _mm256_mul_pd(mhalf, r2);
  };
  constexpr int kP = 4;
  for (; i + 4 * kP <= n; i += 4 * kP) {
    __m256d x[kP];
    for (int u = 0; u < kP; ++u) x[u] = halfSqDist(i + 4 * u);
    scaledExpPackets<kP>(x, cf);
    for (int u = 0; u < kP; ++u) _mm256_storeu_pd(out + i + 4 * u, x[u]);
  }
  for (; i + 4 <= n; i += 4) {
    __m256d x = halfSqDist(i);
    scaledExpPackets<1>(&x, cf);
    _mm256_storeu_pd(out + i, x);
  }
#endif
  for (; i < n; ++i) {
    double diff = A(i, 0) - b[0];
    double r2 = diff * diff;
    for (Eigen::Index d = 1; d < nd; ++d) {
      diff = A(i, d) - b[d];
      r2 = fmaS(diff, diff, r2);
    }
    out[i] = scaledExpScalar(-0.5 * r2, cf);
  }
}

/// RBF part column with the σ² p_i coefficients `cf` (see rbfColumnT).
void rbfColumn(const MatX& A, const double* b, const ScaledExpCoefs& cf, double* out) {
  switch (A.cols()) {
    case 1: return rbfColumnT<1>(A, b, cf, out);
    case 2: return rbfColumnT<2>(A, b, cf, out);
    case 3: return rbfColumnT<3>(A, b, cf, out);
    case 4: return rbfColumnT<4>(A, b, cf, out);
    default: return rbfColumnT<0>(A, b, cf, out);
  }
}

}  // namespace

std::string toString(PartType type) {
  switch (type) {
    case PartType::kRbf: return "rbf";
    case PartType::kMatern52: return "matern52";
    case PartType::kPeriodic: return "periodic";
    case PartType::kLedergerber: return "ledergerber";
  }
  return "unknown";
}

PartType partTypeFromString(const std::string& name) {
  if (name == "rbf" || name == "se" || name == "squared_exponential") return PartType::kRbf;
  if (name == "matern52" || name == "matern") return PartType::kMatern52;
  if (name == "periodic") return PartType::kPeriodic;
  if (name == "ledergerber" || name == "kl" || name == "k_L") return PartType::kLedergerber;
  throw std::invalid_argument("unknown kernel part type '" + name +
                              "' (expected rbf, matern52, periodic or ledergerber)");
}

Kernel Kernel::sum(const std::vector<PartSpec>& parts) {
  std::vector<std::vector<int>> terms;
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) terms.push_back({p});
  return Kernel(parts, terms);
}

Kernel Kernel::product(const std::vector<PartSpec>& parts) {
  std::vector<int> all;
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) all.push_back(p);
  return Kernel(parts, {all});
}

Kernel::Kernel(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms) { build(parts, terms); }

void Kernel::build(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms) {
  if (parts.empty()) throw std::invalid_argument("kernel: no parts");
  std::vector<bool> used(parts.size(), false);
  for (const auto& t : terms) {
    if (t.empty()) throw std::invalid_argument("kernel: empty product term");
    for (int p : t) {
      if (p < 0 || p >= static_cast<int>(parts.size())) throw std::invalid_argument("kernel: term index out of range");
      if (used[p]) throw std::invalid_argument("kernel: a part appears in more than one term");
      used[p] = true;
    }
  }
  for (bool u : used)
    if (!u) throw std::invalid_argument("kernel: a part is in no term");
  parts_.clear();
  names_.clear();
  trainable_.clear();
  std::vector<double> values;
  input_dim_ = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const PartSpec& s = parts[p];
    if (s.active_dims.empty()) throw std::invalid_argument("kernel part " + std::to_string(p) + ": no active dims");
    for (int d : s.active_dims) {
      if (d < 0) throw std::invalid_argument("kernel part: negative active dim");
      input_dim_ = std::max(input_dim_, d + 1);
    }
    Part part{s.type, s.active_dims, static_cast<int>(values.size()), 0, 0};
    const int nd = static_cast<int>(s.active_dims.size());
    const std::string prefix = "p" + std::to_string(p) + "." + toString(s.type) + ".";
    auto add = [&](const std::string& n, double v, bool train) {
      if (!(v > 0.0) || !std::isfinite(v)) {
        throw std::invalid_argument("kernel parameter " + prefix + n + " must be positive and finite, got " +
                                    std::to_string(v));
      }
      values.push_back(v);
      names_.push_back(prefix + n);
      trainable_.push_back(train);
    };
    auto addList = [&](const std::string& n, const std::vector<double>& v, bool train) {
      if (v.size() != 1 && static_cast<int>(v.size()) != nd) {
        throw std::invalid_argument("kernel part " + prefix + n + ": expected 1 or " + std::to_string(nd) +
                                    " values, got " + std::to_string(v.size()));
      }
      if (v.size() == 1) {
        add(n, v[0], train);
      } else {
        for (std::size_t i = 0; i < v.size(); ++i) add(n + "[" + std::to_string(i) + "]", v[i], train);
      }
      return static_cast<int>(v.size());
    };
    if (s.type == PartType::kLedergerber) {
      if (nd != 3) throw std::invalid_argument("ledergerber kernel part needs exactly 3 active dims");
      add("t0", s.sigma2, true);
      add("t1", s.t1, true);
      add("t2", s.t2, true);
    } else {
      add("sigma2", s.sigma2, true);
      part.n_l = addList("l", s.l, true);
      if (s.type == PartType::kPeriodic) part.n_T = addList("T", s.T, s.train_period);
    }
    parts_.push_back(part);
  }
  terms_ = terms;
  theta_ = Eigen::Map<const VecX>(values.data(), static_cast<Eigen::Index>(values.size()));
}

Kernel Kernel::preset(const std::string& name) {
  if (name == "z1") {  // paper eq. (7): k_p(α_i) + k_p(α_j), T = 2π
    PartSpec a{PartType::kPeriodic, {0}, 0.05, {1.0}, {2.0 * kPi}};
    PartSpec b = a;
    b.active_dims = {1};
    return sum({a, b});
  }
  if (name == "z2") {  // paper eq. (8): Matérn-5/2(α_i) + Matérn-5/2(α_j)
    PartSpec a{PartType::kMatern52, {0}, 0.05, {1.0}};
    PartSpec b = a;
    b.active_dims = {1};
    return sum({a, b});
  }
  if (name == "tdoa") {  // paper eq. (9): k_L(x_ki) + k_L(x_kj)
    PartSpec a{PartType::kLedergerber, {0, 1, 2}, 0.05};
    a.t1 = 0.5;
    a.t2 = 4.0;
    PartSpec b = a;
    b.active_dims = {3, 4, 5};
    return sum({a, b});
  }
  throw std::invalid_argument("unknown kernel preset '" + name + "' (expected z1, z2 or tdoa)");
}

std::string Kernel::name() const {
  std::ostringstream os;
  os << '(';
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    if (t) os << '+';
    for (std::size_t i = 0; i < terms_[t].size(); ++i) {
      if (i) os << '*';
      const Part& p = parts_[terms_[t][i]];
      os << toString(p.type) << '[';
      for (std::size_t d = 0; d < p.active_dims.size(); ++d) os << (d ? "," : "") << p.active_dims[d];
      os << ']';
    }
  }
  os << ')';
  return os.str();
}

void Kernel::setTheta(const VecX& theta) {
  if (theta.size() != theta_.size()) throw std::invalid_argument("kernel: wrong number of parameters");
  if (!(theta.array() > 0.0).all() || !theta.allFinite())
    throw std::invalid_argument("kernel: parameters must be positive and finite");
  theta_ = theta;
}

void Kernel::setTrainable(const std::string& name, bool trainable) {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) {
      trainable_[i] = trainable;
      return;
    }
  }
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

std::map<std::string, Parameter> Kernel::params() const {
  std::map<std::string, Parameter> out;
  for (std::size_t i = 0; i < names_.size(); ++i) out[names_[i]] = {theta_[static_cast<Eigen::Index>(i)], trainable_[i]};
  return out;
}

void Kernel::setParam(const std::string& name, double value) {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) {
      if (!(value > 0.0) || !std::isfinite(value))
        throw std::invalid_argument("kernel parameter " + name + " must be positive and finite");
      theta_[static_cast<Eigen::Index>(i)] = value;
      return;
    }
  }
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

double Kernel::param(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return theta_[static_cast<Eigen::Index>(i)];
  throw std::invalid_argument("unknown kernel parameter '" + name + "'");
}

PartSpec Kernel::partSpec(int pi) const {
  const Part& p = parts_[pi];
  PartSpec s;
  s.type = p.type;
  s.active_dims = p.active_dims;
  s.sigma2 = theta_[p.offset];
  if (p.type == PartType::kLedergerber) {
    s.t1 = theta_[p.offset + 1];
    s.t2 = theta_[p.offset + 2];
    s.l.clear();
    s.T.clear();
    return s;
  }
  s.l.assign(theta_.data() + p.offset + 1, theta_.data() + p.offset + 1 + p.n_l);
  if (p.type == PartType::kPeriodic) {
    s.T.assign(theta_.data() + p.offset + 1 + p.n_l, theta_.data() + p.offset + 1 + p.n_l + p.n_T);
    s.train_period = trainable_[p.offset + 1 + p.n_l];
  } else {
    s.T.clear();
  }
  return s;
}

// ---------------------------------------------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------------------------------------------

MatX Kernel::partCross(int pi, const MatX& X1, const MatX& X2) const {
  const Part& p = parts_[pi];
  const MatX A = activeCols(X1, p.active_dims);
  const MatX B = activeCols(X2, p.active_dims);
  const Eigen::Index n1 = A.rows(), n2 = B.rows(), nd = A.cols();
  const double s2 = theta_[p.offset];
  MatX K(n1, n2);
  switch (p.type) {
    case PartType::kRbf:
    case PartType::kMatern52: {
      // ρ² = Σ_d ((a_d − b_d)/l_d)²  (P2, P3)
      MatX As = A, Bs = B;
      for (Eigen::Index d = 0; d < nd; ++d) {
        const double l = theta_[p.lengthscaleIndex(d)];
        As.col(d) /= l;
        Bs.col(d) /= l;
      }
      K.setZero();
      for (Eigen::Index j = 0; j < n2; ++j)
        for (Eigen::Index d = 0; d < nd; ++d) K.col(j).array() += (As.col(d).array() - Bs(j, d)).square();
      if (p.type == PartType::kRbf) {
        K = s2 * (-0.5 * K.array()).exp();
      } else {
        const Eigen::ArrayXXd r = K.array().sqrt() * kSqrt5;  // √5 ρ
        K = s2 * matern52Polynomial(r) * (-r).exp();
      }
      break;
    }
    case PartType::kPeriodic: {
      // Σ_d sin²(π Δ_d / T_d) / l_d²  (P1)
      K.setZero();
      for (Eigen::Index d = 0; d < nd; ++d) {
        const double l = theta_[p.lengthscaleIndex(d)];
        const double T = theta_[p.periodIndex(d)];
        const double c = kPi / T, il2 = 1.0 / (l * l);
        for (Eigen::Index j = 0; j < n2; ++j)
          K.col(j).array() += periodicTerm(A.col(d).array() - B(j, d), c, il2);
      }
      K = s2 * (-2.0 * K.array()).exp();
      break;
    }
    case PartType::kLedergerber: {
      // θ0 exp(−(1 − γ)/θ1 − (n − n')²/θ2), γ = xᵀx'/(n n')  (P4)
      const double t1 = theta_[p.offset + 1], t2 = theta_[p.offset + 2];
      const UnitRows ua = unitRows(A), ub = unitRows(B);
      const VecX &na = ua.norm, &nb = ub.norm;
      K.noalias() = ua.unit * ub.unit.transpose();  // γ
      for (Eigen::Index j = 0; j < n2; ++j)
        K.col(j).array() = ledergerberExponent(K.col(j).array(), na.array() - nb[j], t1, t2);
      K = s2 * K.array().exp();
      break;
    }
  }
  return K;
}

MatX Kernel::cross(const MatX& X1, const MatX& X2, std::vector<MatX>* part_blocks) const {
  if (X1.cols() < input_dim_ || X2.cols() < input_dim_)
    throw std::invalid_argument("kernel: inputs have " + std::to_string(std::min(X1.cols(), X2.cols())) +
                                " columns, the kernel reads " + std::to_string(input_dim_));
  MatX K;
  if (part_blocks) part_blocks->assign(parts_.size(), MatX());
  for (const auto& term : terms_) {
    if (term.size() == 1 && !part_blocks) {
      if (K.size() == 0)
        K = partCross(term[0], X1, X2);
      else
        K += partCross(term[0], X1, X2);
      continue;
    }
    if (K.size() == 0) K = MatX::Zero(X1.rows(), X2.rows());
    MatX prod;
    for (std::size_t i = 0; i < term.size(); ++i) {
      MatX Kp = partCross(term[i], X1, X2);
      if (i == 0)
        prod = Kp;
      else
        prod.array() *= Kp.array();
      if (part_blocks) (*part_blocks)[term[i]] = std::move(Kp);
    }
    K += prod;
  }
  return K;
}

void Kernel::crossInto(const MatX& X1, const MatX& X2, Eigen::Ref<MatX> K) const {
  if (X1.cols() < input_dim_ || X2.cols() < input_dim_)
    throw std::invalid_argument("kernel: inputs have " + std::to_string(std::min(X1.cols(), X2.cols())) +
                                " columns, the kernel reads " + std::to_string(input_dim_));
  const Eigen::Index n1 = X1.rows(), n2 = X2.rows();
  if (K.rows() != n1 || K.cols() != n2) throw std::invalid_argument("kernel crossInto: output has the wrong size");
  // Per part: the active columns prepared once (P1–P4 in the same operation order as partCross), then one column
  // of the part per row of X2, vectorized over the rows of X1.
  struct Prepared {
    MatX A, B;     // rbf/matern: columns divided by l; periodic: raw; ledergerber: unit vectors
    MatX Bt;       // rbf: Bᵀ (row j of B contiguous)
    ScaledExpCoefs cf{1.0};  // rbf: σ² p_i (P32)
    VecX na, nb;   // ledergerber: norms
  };
  std::vector<Prepared> prep(parts_.size());
  for (std::size_t pi = 0; pi < parts_.size(); ++pi) {
    const Part& p = parts_[pi];
    Prepared& q = prep[pi];
    q.A = activeCols(X1, p.active_dims);
    q.B = activeCols(X2, p.active_dims);
    if (p.type == PartType::kRbf || p.type == PartType::kMatern52) {
      for (Eigen::Index d = 0; d < q.A.cols(); ++d) {
        const double l = theta_[p.lengthscaleIndex(d)];
        q.A.col(d) /= l;
        q.B.col(d) /= l;
      }
      q.Bt = q.B.transpose();
      q.cf = ScaledExpCoefs(theta_[p.offset]);
    } else if (p.type == PartType::kLedergerber) {
      UnitRows ua = unitRows(q.A), ub = unitRows(q.B);
      q.na = std::move(ua.norm), q.A = std::move(ua.unit);
      q.nb = std::move(ub.norm), q.B = std::move(ub.unit);
    }
  }
  Eigen::ArrayXd term(n1), part(n1), scratch(n1);
  auto evalPart = [&](int pi, Eigen::Index j, double* out_data) {
    Eigen::Map<Eigen::ArrayXd> out(out_data, n1);
    const Part& p = parts_[static_cast<std::size_t>(pi)];
    const Prepared& q = prep[static_cast<std::size_t>(pi)];
    const double s2 = theta_[p.offset];
    const Eigen::Index nd = q.A.cols();
    switch (p.type) {
      case PartType::kRbf:
      case PartType::kMatern52: {  // ρ² = Σ_d (a_d/l_d − b_d/l_d)²  (P2, P3)
        if (p.type == PartType::kMatern52) {
          out = (q.A.col(0).array() - q.B(j, 0)).square();
          for (Eigen::Index d = 1; d < nd; ++d) out += (q.A.col(d).array() - q.B(j, d)).square();
        }
        if (p.type == PartType::kRbf) {
          rbfColumn(q.A, q.Bt.col(j).data(), q.cf, out.data());
        } else {
          scratch = out.sqrt() * kSqrt5;  // √5 ρ
          out = scratch;
          scaledExpInPlace(out.data(), n1, -1.0, 1.0);
          out *= s2 * matern52Polynomial(scratch);
        }
        break;
      }
      case PartType::kPeriodic: {  // Σ_d sin²(π Δ_d / T_d) / l_d²  (P1)
        out.setZero();
        for (Eigen::Index d = 0; d < nd; ++d) {
          const double l = theta_[p.lengthscaleIndex(d)];
          const double T = theta_[p.periodIndex(d)];
          const double c = kPi / T, il2 = 1.0 / (l * l);
          out += periodicTerm(q.A.col(d).array() - q.B(j, d), c, il2);
        }
        scaledExpInPlace(out.data(), n1, -2.0, s2);
        break;
      }
      case PartType::kLedergerber: {  // θ0 exp(−(1 − γ)/θ1 − (n − n')²/θ2), γ = xᵀx'/(n n')  (P4)
        const double t1 = theta_[p.offset + 1], t2 = theta_[p.offset + 2];
        const auto gamma = q.A.col(0).array() * q.B(j, 0) + q.A.col(1).array() * q.B(j, 1) +
                           q.A.col(2).array() * q.B(j, 2);
        out = ledergerberExponent(gamma, q.na.array() - q.nb[j], t1, t2);
        scaledExpInPlace(out.data(), n1, 1.0, s2);
        break;
      }
    }
  };
  for (Eigen::Index j = 0; j < n2; ++j) {
    // K = Σ_terms Π_parts (P5), summed in the order of cross(); the first term is written into K directly
    auto Kj = K.col(j).array();
    for (std::size_t t = 0; t < terms_.size(); ++t) {
      const auto& tm = terms_[t];
      double* dst = t == 0 ? K.col(j).data() : term.data();
      evalPart(tm[0], j, dst);
      Eigen::Map<Eigen::ArrayXd> prod(dst, n1);
      for (std::size_t i = 1; i < tm.size(); ++i) {
        evalPart(tm[i], j, part.data());
        prod *= part;
      }
      if (t > 0) Kj += term;
    }
  }
}

void Kernel::crossColumn(const MatX& X1, const Eigen::Ref<const RowVecX>& x, Eigen::Ref<VecX> out) const {
  if (X1.cols() < input_dim_ || x.size() < input_dim_)
    throw std::invalid_argument("kernel: inputs have too few columns for the kernel");
  if (out.size() != X1.rows()) throw std::invalid_argument("kernel crossColumn: output has the wrong size");
  constexpr int kChunk = 64;
  using Chunk = Eigen::Array<double, Eigen::Dynamic, 1, 0, kChunk, 1>;  // stack storage, no allocation
  const Eigen::Index n1 = X1.rows();
  out.setZero();
  for (Eigen::Index i0 = 0; i0 < n1; i0 += kChunk) {
    const Eigen::Index c = std::min<Eigen::Index>(kChunk, n1 - i0);
    for (const auto& term : terms_) {
      Chunk prod = Chunk::Ones(c);
      for (int pi : term) {
        const Part& p = parts_[pi];
        const double s2 = theta_[p.offset];
        const Eigen::Index nd = static_cast<Eigen::Index>(p.active_dims.size());
        Chunk acc = Chunk::Zero(c);
        switch (p.type) {
          case PartType::kRbf:
          case PartType::kMatern52: {  // P2, P3
            for (Eigen::Index d = 0; d < nd; ++d) {
              const int dim = p.active_dims[static_cast<std::size_t>(d)];
              const double il = 1.0 / theta_[p.lengthscaleIndex(d)];
              acc += ((X1.col(dim).segment(i0, c).array() - x[dim]) * il).square();
            }
            if (p.type == PartType::kRbf) {
              prod *= s2 * (-0.5 * acc).exp();
            } else {
              const Chunk r = acc.sqrt() * kSqrt5;
              prod *= s2 * matern52Polynomial(r) * (-r).exp();
            }
            break;
          }
          case PartType::kPeriodic: {  // P1
            for (Eigen::Index d = 0; d < nd; ++d) {
              const int dim = p.active_dims[static_cast<std::size_t>(d)];
              const double l = theta_[p.lengthscaleIndex(d)];
              const double T = theta_[p.periodIndex(d)];
              acc += periodicTerm(X1.col(dim).segment(i0, c).array() - x[dim], kPi / T, 1.0 / (l * l));
            }
            prod *= s2 * (-2.0 * acc).exp();
            break;
          }
          case PartType::kLedergerber: {  // P4
            const double t1 = theta_[p.offset + 1], t2 = theta_[p.offset + 2];
            const int d0 = p.active_dims[0], d1 = p.active_dims[1], d2 = p.active_dims[2];
            const double nb = std::sqrt(x[d0] * x[d0] + x[d1] * x[d1] + x[d2] * x[d2]);
            const auto a0 = X1.col(d0).segment(i0, c).array(), a1 = X1.col(d1).segment(i0, c).array(),
                       a2 = X1.col(d2).segment(i0, c).array();
            const Chunk na = (a0.square() + a1.square() + a2.square()).sqrt();
            if (nb < 1e-12 || na.minCoeff() < 1e-12)
              throw std::invalid_argument("ledergerber kernel: input vector of zero norm (k_L is undefined at x = 0)");
            const Chunk gamma = (a0 * x[d0] + a1 * x[d1] + a2 * x[d2]) / (na * nb);
            prod *= s2 * ledergerberExponent(gamma, na - nb, t1, t2).exp();
            break;
          }
        }
      }
      out.segment(i0, c).array() += prod;
    }
  }
}

double Kernel::operator()(const Eigen::Ref<const RowVecX>& x, const Eigen::Ref<const RowVecX>& xp) const {
  return cross(MatX(x), MatX(xp))(0, 0);
}

double Kernel::diagValue() const {
  double k = 0.0;
  for (const auto& term : terms_) {
    double prod = 1.0;
    for (int p : term) prod *= theta_[parts_[p].offset];
    k += prod;
  }
  return k;
}

VecX Kernel::diag(const MatX& X) const { return VecX::Constant(X.rows(), diagValue()); }

void Kernel::accumulateDiagGradient(double sum_g, VecX& grad_theta) const {
  for (const auto& term : terms_) {
    for (int p : term) {
      double others = 1.0;
      for (int q : term)
        if (q != p) others *= theta_[parts_[q].offset];
      grad_theta[parts_[p].offset] += sum_g * others;  // ∂k(x,x)/∂σ²_p = Π_{q≠p} σ²_q
    }
  }
}

void Kernel::accumulateCrossGradient(const MatX& X1, const MatX& X2, const MatX& G,
                                     const std::vector<MatX>& part_blocks, VecX& grad_theta, MatX* grad_X1) const {
  if (static_cast<int>(part_blocks.size()) != numParts())
    throw std::invalid_argument("kernel gradient: part_blocks missing (call cross(X1, X2, &blocks))");
  for (const auto& term : terms_) {
    for (int p : term) {
      if (term.size() == 1) {
        partGradient(p, X1, X2, G, part_blocks[p], grad_theta, grad_X1);
      } else {
        MatX H = G;  // P5: ∂(Π k_q)/∂θ_p = (Π_{q≠p} k_q) ∂k_p/∂θ_p
        for (int q : term)
          if (q != p) H.array() *= part_blocks[q].array();
        partGradient(p, X1, X2, H, part_blocks[p], grad_theta, grad_X1);
      }
    }
  }
}

void Kernel::partGradient(int pi, const MatX& X1, const MatX& X2, const MatX& H, const MatX& Kp, VecX& grad_theta,
                          MatX* grad_X1) const {
  const Part& p = parts_[pi];
  const MatX A = activeCols(X1, p.active_dims);
  const MatX B = activeCols(X2, p.active_dims);
  const Eigen::Index n2 = B.rows(), nd = A.cols();
  const double s2 = theta_[p.offset];
  const MatX W = H.cwiseProduct(Kp);  // H ∘ k
  const double sumW = W.sum();
  grad_theta[p.offset] += sumW / s2;  // ∂k/∂σ² = k/σ²
  switch (p.type) {
    case PartType::kRbf:
    case PartType::kMatern52: {
      // weight w multiplying Δ_d/l_d² in ∂k/∂x_d = −w Δ_d / l_d²  and  ∂k/∂l_d = w Δ_d² / l_d³
      MatX Wg_matern;
      if (p.type == PartType::kMatern52) {
        // P9: Matérn-5/2, g = (5/3) σ² (1 + √5ρ) e^{−√5ρ}
        MatX R2 = MatX::Zero(A.rows(), n2);
        for (Eigen::Index d = 0; d < nd; ++d) {
          const double l = theta_[p.lengthscaleIndex(d)];
          for (Eigen::Index j = 0; j < n2; ++j) R2.col(j).array() += ((A.col(d).array() - B(j, d)) / l).square();
        }
        const Eigen::ArrayXXd r = R2.array().sqrt() * kSqrt5;
        Wg_matern = H.array() * ((5.0 / 3.0) * s2 * (1.0 + r) * (-r).exp());
      }
      const MatX& Wg = p.type == PartType::kRbf ? W : Wg_matern;  // P8: RBF: w = H ∘ k
      // Σ_j w_ij Δ_ij = a_i (Σ_j w_ij) − (W b)_i and Σ_ij w_ij Δ_ij² = Σ_i rs_i a_i² − 2 aᵀ(W b) + Σ_j cs_j b_j²:
      // one GEMM W·B (n1×n2 · n2×d) instead of d passes over the n1×n2 block. Inputs are centred on A's column
      // means first (Δ is unchanged) to keep the cancellation in the expanded square small.
      MatX Ac = A, Bc = B;
      for (Eigen::Index d = 0; d < nd; ++d) {
        const double centre = A.rows() > 0 ? A.col(d).mean() : 0.0;
        Ac.col(d).array() -= centre;
        Bc.col(d).array() -= centre;
      }
      const VecX rs = Wg.rowwise().sum();
      const VecX cs = Wg.colwise().sum().transpose();
      MatX WB(A.rows(), nd);
      WB.noalias() = Wg * Bc;
      for (Eigen::Index d = 0; d < nd; ++d) {
        const Eigen::Index li = p.lengthscaleIndex(d);
        const double l = theta_[li];
        const auto a = Ac.col(d).array();
        const double acc = (rs.array() * a.square()).sum() - 2.0 * (a * WB.col(d).array()).sum() +
                           (cs.array() * Bc.col(d).array().square()).sum();
        grad_theta[li] += acc / (l * l * l);
        if (grad_X1) grad_X1->col(p.active_dims[d]) -= ((a * rs.array() - WB.col(d).array()) / (l * l)).matrix();
      }
      break;
    }
    case PartType::kPeriodic: {
      // P7: u = πΔ/T; ∂k/∂l = 4k sin²u / l³; ∂k/∂T = k (2/l²) sin 2u · πΔ/T²; ∂k/∂x = −k (2/l²) sin 2u · π/T
      Eigen::ArrayXd gx(A.rows()), delta(A.rows()), su(A.rows()), ws2(A.rows());
      for (Eigen::Index d = 0; d < nd; ++d) {
        const Eigen::Index li = p.lengthscaleIndex(d);
        const Eigen::Index ti = p.periodIndex(d);
        const double l = theta_[li], T = theta_[ti], c = kPi / T;
        double acc_l = 0.0, acc_T = 0.0;
        gx.setZero();
        for (Eigen::Index j = 0; j < n2; ++j) {
          delta = A.col(d).array() - B(j, d);
          su = (c * delta).sin();
          acc_l += (W.col(j).array() * su.square()).sum();
          ws2 = W.col(j).array() * 2.0 * su * (c * delta).cos();  // w sin 2u
          acc_T += (ws2 * delta).sum();
          gx += ws2;
        }
        grad_theta[li] += 4.0 * acc_l / (l * l * l);
        grad_theta[ti] += (2.0 / (l * l)) * c / T * acc_T;
        if (grad_X1) grad_X1->col(p.active_dims[d]) -= ((2.0 / (l * l)) * c * gx).matrix();
      }
      break;
    }
    case PartType::kLedergerber: {
      // P10: ∂k/∂θ1 = k(1−γ)/θ1², ∂k/∂θ2 = k(n−n')²/θ2², ∂k/∂x = k[(x'/(nn') − γx/n²)/θ1 − 2(n−n')/θ2 · x/n]
      const double t1 = theta_[p.offset + 1], t2 = theta_[p.offset + 2];
      const UnitRows ua = unitRows(A), ub = unitRows(B);
      const VecX &na = ua.norm, &nb = ub.norm;
      const MatX &Ua = ua.unit, &Ub = ub.unit;
      const MatX gamma = Ua * Ub.transpose();
      MatX dn2(A.rows(), n2);  // (n − n')
      for (Eigen::Index j = 0; j < n2; ++j) dn2.col(j) = na.array() - nb[j];
      grad_theta[p.offset + 1] += (W.array() * (1.0 - gamma.array())).sum() / (t1 * t1);
      grad_theta[p.offset + 2] += (W.array() * dn2.array().square()).sum() / (t2 * t2);
      if (grad_X1) {
        const MatX WUb = W * Ub;                                         // Σ_j w_ij x'_j/n'_j
        const VecX wg = (W.array() * gamma.array()).rowwise().sum();   // Σ_j w_ij γ_ij
        const VecX wdn = (W.array() * dn2.array()).rowwise().sum();    // Σ_j w_ij (n_i − n'_j)
        for (Eigen::Index d = 0; d < 3; ++d) {
          const VecX g = (WUb.col(d).array() / na.array() / t1 - wg.array() * A.col(d).array() / na.array().square() / t1 -
                          2.0 * wdn.array() / t2 * A.col(d).array() / na.array())
                             .matrix();
          grad_X1->col(p.active_dims[d]) += g;
        }
      }
      break;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// JSON
// ---------------------------------------------------------------------------------------------------------------

nlohmann::json Kernel::toJson() const {
  nlohmann::json parts = nlohmann::json::array();
  for (int p = 0; p < numParts(); ++p) {
    const PartSpec s = partSpec(p);
    nlohmann::json jp;
    jp["type"] = toString(s.type);
    jp["active_dims"] = s.active_dims;
    if (s.type == PartType::kLedergerber) {
      jp["t0"] = s.sigma2;
      jp["t1"] = s.t1;
      jp["t2"] = s.t2;
    } else {
      jp["sigma2"] = s.sigma2;
      jp["l"] = s.l;
      if (s.type == PartType::kPeriodic) {
        jp["T"] = s.T;
        jp["train_period"] = s.train_period;
      }
    }
    parts.push_back(jp);
  }
  nlohmann::json fixed = nlohmann::json::array();
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (!trainable_[i]) fixed.push_back(names_[i]);
  return {{"combination", "sum_of_products"}, {"terms", terms_}, {"parts", parts}, {"fixed", fixed},
          {"name", name()}};
}

namespace {
/// An array of small non-negative integers (dimension or part indices), checked before conversion: get<int>() of
/// a value like 1e300 would overflow (undefined behaviour).
std::vector<int> indicesFromJson(const nlohmann::json& j, const char* what) {
  if (!j.is_array()) throw std::invalid_argument(std::string(what) + ": expected an array of indices");
  std::vector<int> out;
  for (const auto& v : j) {
    if (!v.is_number_integer() || v.get<std::int64_t>() < 0 || v.get<std::int64_t>() > 1000)
      throw std::invalid_argument(std::string(what) + ": expected integer indices in [0, 1000], got " + v.dump());
    out.push_back(static_cast<int>(v.get<std::int64_t>()));
  }
  return out;
}
}  // namespace

Kernel Kernel::fromJson(const nlohmann::json& j) {
  try {
    std::vector<PartSpec> specs;
    for (const auto& jp : j.at("parts")) {
      PartSpec s;
      s.type = partTypeFromString(jp.at("type").get<std::string>());
      s.active_dims = indicesFromJson(jp.at("active_dims"), "active_dims");
      // Either our own layout or the fixture layout (parameters in a "paper" block; FIXTURES.md §2).
      const nlohmann::json& src = jp.contains("paper") ? jp.at("paper") : jp;
      if (s.type == PartType::kLedergerber) {
        s.sigma2 = src.at("t0").get<double>();
        s.t1 = src.at("t1").get<double>();
        s.t2 = src.at("t2").get<double>();
      } else {
        s.sigma2 = src.at("sigma2").get<double>();
        s.l = src.at("l").get<std::vector<double>>();
        if (s.type == PartType::kPeriodic) {
          s.T = src.at("T").get<std::vector<double>>();
          s.train_period = jp.value("train_period", false);
        }
      }
      specs.push_back(s);
    }
    std::vector<std::vector<int>> terms;
    const std::string comb = j.value("combination", std::string("sum"));
    if (comb == "sum") {
      for (int p = 0; p < static_cast<int>(specs.size()); ++p) terms.push_back({p});
    } else if (comb == "product") {
      terms.emplace_back();
      for (int p = 0; p < static_cast<int>(specs.size()); ++p) terms[0].push_back(p);
    } else if (comb == "sum_of_products") {
      for (const auto& t : j.at("terms")) terms.push_back(indicesFromJson(t, "terms"));
    } else {
      throw std::invalid_argument("unknown combination '" + comb + "'");
    }
    Kernel k(specs, terms);
    if (j.contains("fixed"))
      for (const auto& n : j.at("fixed")) k.setTrainable(n.get<std::string>(), false);
    return k;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("kernel JSON: ") + e.what());
  }
}

}  // namespace uwb::gp
