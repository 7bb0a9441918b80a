/** @file Multilateration.cpp
 *  @brief Robust Gauss–Newton TDoA multilateration (docs/math/filter.md F16, F16b).
 */
#include "uwb/filter/Multilateration.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "uwb/model/TdoaModel.h"

namespace uwb {

void DistinctAnchors::insert(int id) {
  if (std::find(ids_.begin(), ids_.begin() + n_, id) != ids_.begin() + n_) return;
  if (n_ < static_cast<int>(ids_.size())) ids_[static_cast<std::size_t>(n_++)] = id;
}

namespace {

/// What one Huber-IRLS Gauss–Newton run from a start ended with.
template <class Vec, class Mat>
struct GaussNewtonRun {
  Vec x;
  Mat A;  ///< the normal matrix of the last iteration (without the 1e-9 I of the solve)
  double cost = 0.0;
  MultilaterationResult res;  ///< iterations, n_used, rms_residual_m
};

/// (F16) The Huber-IRLS Gauss–Newton iteration of every multilateration, from x: per sample the TDoA at
/// position(x, s) (M3), r = z − h − extra and the row ∂h/∂x from row(x, s, J, &row), which returns `extra` (what the
/// model adds to h beyond the geometry: the floor-level delays of F16f, else 0); then regularize(A, g, cost, x) for
/// what is not a sample (fixed coordinates, priors) and limit(step). The one implementation of F16, F16b, F16c, F16f.
template <class Vec, class Mat, class Position, class Row, class Regularize, class Limit>
GaussNewtonRun<Vec, Mat> huberGaussNewton(Vec x, const std::vector<MultilaterationSample>& samples,
                                         const AnchorTable& anchors, const Vec3& b_t_tag, double huber_k_m,
                                         int max_iterations, std::size_t min_used, Position&& position, Row&& row,
                                         Regularize&& regularize, Limit&& limit) {
  GaussNewtonRun<Vec, Mat> run;
  run.A = Mat::Zero();
  Vec r_row = Vec::Zero();
  for (int it = 0; it < max_iterations; ++it) {
    run.A.setZero();
    Vec g = Vec::Zero();
    run.cost = 0.0;
    double wr2 = 0.0, wsum = 0.0;
    std::size_t n = 0;
    for (const MultilaterationSample& s : samples) {
      const Moments3* a = anchors.find(s.z.id_a);
      const Moments3* b = anchors.find(s.z.id_b);
      if (!a || !b) continue;
      TdoaJacobians J;
      const std::optional<double> h = evaluateTdoa(position(x, s), s.w_q_b, a->m, b->m, {b_t_tag, 1e-6}, &J);
      if (!h) continue;
      const double extra = row(x, s, J, &r_row);
      // (F16) r = z − h(p_i); Huber weight on |r|
      const double r = s.z.tdoa_m - *h - extra;
      const double ar = std::abs(r);
      const double w = ar <= huber_k_m ? 1.0 : huber_k_m / ar;
      run.cost += ar <= huber_k_m ? 0.5 * r * r : huber_k_m * (ar - 0.5 * huber_k_m);
      run.A.noalias() += w * r_row * r_row.transpose();
      g.noalias() += w * r_row * r;
      wr2 += w * r * r;
      wsum += w;
      ++n;
    }
    if (n < min_used) break;
    regularize(run.A, g, run.cost, x);
    const Eigen::LDLT<Mat> ldlt(run.A + 1e-9 * Mat::Identity());
    Vec step = ldlt.solve(g);
    if (!step.allFinite()) break;
    limit(step);
    x += step;
    run.res.iterations = it + 1;
    run.res.n_used = n;
    run.res.rms_residual_m = std::sqrt(wr2 / std::max(wsum, 1e-12));
    if (step.norm() < 1e-5) break;
  }
  run.x = x;
  return run;
}

/// Whether guess k repeats the x and y of an earlier guess: on the floor (z fixed) it is the same start (F16c).
bool sameFloorStartAsEarlier(const std::vector<Vec3>& guesses, std::size_t k) {
  const auto same_xy = [&](const Vec3& g) { return g.x() == guesses[k].x() && g.y() == guesses[k].y(); };
  return std::any_of(guesses.begin(), guesses.begin() + static_cast<std::ptrdiff_t>(k), same_xy);
}

/// Huber-IRLS Gauss–Newton over N unknowns: N = 3 solves p0 (F16), N = 6 solves (p0, v0) with the body at
/// p0 + v0 (t_i − t_ref) + d_i (F16b).
/// fixed_z (N = 3 only): the body origin's height is known (on the floor), the solve is over x and y (F16c).
template <int N>
std::optional<MultilaterationResult> solve(const std::vector<MultilaterationSample>& samples, const AnchorTable& anchors,
                                           const Vec3& b_t_tag, const std::vector<Vec3>& initial_guesses,
                                           double t_ref_s, double huber_k_m, int max_iterations,
                                           std::optional<double> fixed_z = std::nullopt) {
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  constexpr std::size_t kMinUsed = N == 3 ? 4 : 8;
  if (samples.size() < kMinUsed) return std::nullopt;
  const auto position = [&](const VecN& x, const MultilaterationSample& s) {
    Vec3 w_p = x.template head<3>() + s.w_d_b;
    if constexpr (N == 6) w_p += (s.z.t_s - t_ref_s) * x.template tail<3>();
    return w_p;
  };
  const auto row = [&](const VecN&, const MultilaterationSample& s, const TdoaJacobians& J, VecN* out) {
    out->template head<3>() = J.J_z_p_b;
    if constexpr (N == 6) out->template tail<3>() = (s.z.t_s - t_ref_s) * J.J_z_p_b;  // ∂h/∂v0 (F16b)
    return 0.0;
  };
  const auto regularize = [&](MatN& A, VecN& g, double&, const VecN&) {
    if (!fixed_z) return;
    // (F16c) z is not an unknown: its row and column become the identity, its step zero
    A.row(2).setZero();
    A.col(2).setZero();
    A(2, 2) = 1.0;
    g(2) = 0.0;
  };
  const auto limit = [](VecN& step) {
    // limit the step: TDoA geometry can be strongly nonlinear far from the anchors' hull
    const double sn = step.template head<3>().norm();
    if (sn > 2.0) step.template head<3>() *= 2.0 / sn;
    if constexpr (N == 6) {
      const double vn = step.template tail<3>().norm();
      if (vn > 2.0) step.template tail<3>() *= 2.0 / vn;
    }
  };
  std::optional<MultilaterationResult> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < initial_guesses.size(); ++k) {
    // (F16c) guesses that differ only in height are one start on the floor: solved once (same result, a third of
    // the cost with the default guesses, which share x and y)
    if (fixed_z && sameFloorStartAsEarlier(initial_guesses, k)) continue;
    VecN x0 = VecN::Zero();
    x0.template head<3>() = initial_guesses[k];
    if (fixed_z) x0(2) = *fixed_z;
    GaussNewtonRun<VecN, MatN> run = huberGaussNewton<VecN, MatN>(
        x0, samples, anchors, b_t_tag, huber_k_m, max_iterations, kMinUsed, position, row, regularize, limit);
    if (run.res.n_used < kMinUsed || !run.x.allFinite()) continue;
    if (run.cost < best_cost) {
      best_cost = run.cost;
      MultilaterationResult& res = run.res;
      res.w_p0 = run.x.template head<3>();
      const MatN Ainv = (run.A + 1e-9 * MatN::Identity()).inverse() * (res.rms_residual_m * res.rms_residual_m);
      res.covariance = Ainv.template topLeftCorner<3, 3>();
      if constexpr (N == 6) {
        res.w_v0 = run.x.template tail<3>();
        res.covariance_pv = Ainv;
      }
      best = res;
    }
  }
  return best;
}

}  // namespace

std::optional<MultilaterationResult> multilaterate(const std::vector<MultilaterationSample>& samples,
                                                   const AnchorTable& anchors, const Vec3& b_t_tag,
                                                   const std::vector<Vec3>& initial_guesses, double huber_k_m,
                                                   int max_iterations) {
  return solve<3>(samples, anchors, b_t_tag, initial_guesses, 0.0, huber_k_m, max_iterations);
}

std::optional<MultilaterationResult> multilaterateOnFloor(const std::vector<MultilaterationSample>& samples,
                                                          const AnchorTable& anchors, const Vec3& b_t_tag,
                                                          const std::vector<Vec3>& initial_guesses, double floor_z_m,
                                                          double huber_k_m, int max_iterations) {
  std::optional<MultilaterationResult> r =
      solve<3>(samples, anchors, b_t_tag, initial_guesses, 0.0, huber_k_m, max_iterations, floor_z_m);
  if (r) {
    r->covariance.row(2).setZero();
    r->covariance.col(2).setZero();
  }
  return r;
}

namespace {

bool isFloorLevelAnchor(const std::vector<unsigned char>& floor_level, int id) {
  return id >= 0 && static_cast<std::size_t>(id) < floor_level.size() && floor_level[id] != 0;
}

/// (F16f) The unknowns of the floor solve with delays: u = (x, y, g_1 … g_L).
struct FloorDelayColumns {
  std::vector<int> column;  ///< by anchor id: the delay's column in u, −1 for none
  int n_other = 0;          ///< anchors seen that are not floor-level
  int n_cols = 2;           ///< columns of u
};

FloorDelayColumns floorDelayColumns(const std::vector<MultilaterationSample>& samples, const AnchorTable& anchors,
                                    const std::vector<unsigned char>& floor_level) {
  FloorDelayColumns c;
  std::vector<unsigned char> other_seen;
  for (const MultilaterationSample& s : samples) {
    if (!anchors.find(s.z.id_a) || !anchors.find(s.z.id_b)) continue;
    for (const int id : {s.z.id_a, s.z.id_b}) {
      const auto i = static_cast<std::size_t>(id);
      if (isFloorLevelAnchor(floor_level, id)) {
        if (c.column.size() <= i) c.column.resize(i + 1, -1);
        if (c.column[i] < 0) c.column[i] = c.n_cols++;
      } else {
        if (other_seen.size() <= i) other_seen.resize(i + 1, 0);
        if (!other_seen[i]) ++c.n_other;
        other_seen[i] = 1;
      }
    }
  }
  return c;
}

/// (F16f) At most this many delays: a fixed-size system, no heap; unused columns are identity rows with a zero step.
constexpr int kMaxFloorDelays = 8;
using MatU = Eigen::Matrix<double, kMaxFloorDelays + 2, kMaxFloorDelays + 2>;
using VecU = Eigen::Matrix<double, kMaxFloorDelays + 2, 1>;

/// (F16f) One start's run as a result: the position on the floor, its covariance, the delays by anchor id; nullopt
/// when a delay lies outside its range (not a longer first path: a poor geometry fitted the delays to something else).
std::optional<MultilaterationResult> floorDelayResult(GaussNewtonRun<VecU, MatU>& run, const FloorDelayColumns& columns,
                                                      double floor_z_m) {
  const auto implausible = [](double g) { return g < kMinFloorDelay_m || g > kMaxFloorDelay_m; };
  if (std::any_of(run.x.data() + 2, run.x.data() + columns.n_cols, implausible)) return std::nullopt;
  MultilaterationResult& res = run.res;
  res.w_p0 = Vec3(run.x(0), run.x(1), floor_z_m);
  const MatU Ainv = (run.A + 1e-9 * MatU::Identity()).ldlt().solve(MatU::Identity()) *
                    (res.rms_residual_m * res.rms_residual_m);
  res.covariance.setZero();
  res.covariance.topLeftCorner<2, 2>() = Ainv.topLeftCorner<2, 2>();
  res.anchor_delay_m.assign(columns.column.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t id = 0; id < columns.column.size(); ++id)
    if (columns.column[id] >= 0) res.anchor_delay_m[id] = run.x(columns.column[id]);
  return res;
}

/// (F16f) The floor solve over u = (x, y, g_1 … g_L), from each start that differs in x and y; the best plausible run.
std::optional<MultilaterationResult> solveFloorWithDelays(const std::vector<MultilaterationSample>& samples,
                                                          const AnchorTable& anchors, const Vec3& b_t_tag,
                                                          const std::vector<Vec3>& initial_guesses, double floor_z_m,
                                                          const std::vector<unsigned char>& floor_level,
                                                          const FloorDelayColumns& columns, double huber_k_m,
                                                          int max_iterations) {
  const std::vector<int>& column = columns.column;
  const int n_cols = columns.n_cols;
  const auto delayColumn = [&](int id) {
    return isFloorLevelAnchor(floor_level, id) && static_cast<std::size_t>(id) < column.size()
               ? column[static_cast<std::size_t>(id)]
               : -1;
  };
  // weak prior g ~ N(0, (5 m)²) in the units of the Huber cost (residual scale k): only an anchor whose delay the
  // batch does not determine (seen in one pair only) is held by it
  constexpr double kDelayPriorSigma_m = 5.0;
  const double lambda = (huber_k_m / kDelayPriorSigma_m) * (huber_k_m / kDelayPriorSigma_m);
  constexpr std::size_t kMinUsed = 4;
  const auto position = [&](const VecU& u, const MultilaterationSample& s) -> Vec3 {
    return Vec3(u(0), u(1), floor_z_m) + s.w_d_b;
  };
  const auto row = [&](const VecU& u, const MultilaterationSample& s, const TdoaJacobians& J, VecU* out) {
    // (F16f) z = h(p) + g_B − g_A: the delay of B lengthens d_B, the delay of A lengthens d_A
    out->setZero();
    (*out)(0) = J.J_z_p_b(0);
    (*out)(1) = J.J_z_p_b(1);
    double extra = 0.0;
    if (const int cb = delayColumn(s.z.id_b); cb >= 0) {
      (*out)(cb) += 1.0;
      extra += u(cb);
    }
    if (const int ca = delayColumn(s.z.id_a); ca >= 0) {
      (*out)(ca) -= 1.0;
      extra -= u(ca);
    }
    return extra;
  };
  const auto regularize = [&](MatU& A, VecU& g, double& cost, const VecU& u) {
    for (int c = 2; c < n_cols; ++c) {
      A(c, c) += lambda;
      g(c) -= lambda * u(c);
      cost += 0.5 * lambda * u(c) * u(c);
    }
    for (int c = n_cols; c < kMaxFloorDelays + 2; ++c) A(c, c) = 1.0;  // unused columns: a zero step
  };
  const auto limit = [](VecU& step) {
    const double sn = step.head<2>().norm();  // as in solve(): at most 2 m of position per step
    if (sn > 2.0) step.head<2>() *= 2.0 / sn;
  };
  std::optional<MultilaterationResult> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < initial_guesses.size(); ++k) {
    if (sameFloorStartAsEarlier(initial_guesses, k)) continue;
    VecU u0 = VecU::Zero();
    u0(0) = initial_guesses[k].x();
    u0(1) = initial_guesses[k].y();
    GaussNewtonRun<VecU, MatU> run = huberGaussNewton<VecU, MatU>(
        u0, samples, anchors, b_t_tag, huber_k_m, max_iterations, kMinUsed, position, row, regularize, limit);
    if (run.res.n_used < kMinUsed || !run.x.allFinite() || !(run.cost < best_cost)) continue;
    std::optional<MultilaterationResult> res = floorDelayResult(run, columns, floor_z_m);
    if (!res) continue;
    best_cost = run.cost;
    best = std::move(res);
  }
  return best;
}

}  // namespace

std::optional<MultilaterationResult> multilaterateOnFloorWithDelays(
    const std::vector<MultilaterationSample>& samples, const AnchorTable& anchors, const Vec3& b_t_tag,
    const std::vector<Vec3>& initial_guesses, double floor_z_m, const std::vector<unsigned char>& floor_level,
    double huber_k_m, int max_iterations) {
  // (F16f) unknowns u = (x, y, g_1 … g_L): one range delay per floor-level anchor seen in the batch
  const FloorDelayColumns columns = floorDelayColumns(samples, anchors, floor_level);
  // more floor-level anchors in view than kMaxFloorDelays: the plain solve
  if (columns.n_other < 3 || columns.n_cols - 2 > kMaxFloorDelays) return std::nullopt;
  if (columns.n_cols == 2)
    return multilaterateOnFloor(samples, anchors, b_t_tag, initial_guesses, floor_z_m, huber_k_m, max_iterations);
  return solveFloorWithDelays(samples, anchors, b_t_tag, initial_guesses, floor_z_m, floor_level, columns, huber_k_m,
                              max_iterations);
}

std::optional<MultilaterationResult> multilaterateMoving(const std::vector<MultilaterationSample>& samples,
                                                         const AnchorTable& anchors, const Vec3& b_t_tag,
                                                         const std::vector<Vec3>& initial_guesses, double t_ref_s,
                                                         double huber_k_m, int max_iterations) {
  if (samples.empty()) return std::nullopt;
  const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end(), [](const auto& a, const auto& b) {
    return a.z.t_s < b.z.t_s;
  });
  if (hi->z.t_s - lo->z.t_s < 0.1) return std::nullopt;
  return solve<6>(samples, anchors, b_t_tag, initial_guesses, t_ref_s, huber_k_m, max_iterations);
}

}  // namespace uwb
