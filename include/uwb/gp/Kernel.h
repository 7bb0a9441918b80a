/** @file Kernel.h
 *  @brief Composite GP kernels: sums of products of parts, each part acting on its own input columns.
 *
 *  Parts (docs/math/gp.md P1–P4; paper III-B):
 *   - periodic    k = σ² exp(−2 Σ_d sin²(π|x_d − x'_d|/T_d) / l_d²)              (paper k_p, eq. 7; P1)
 *   - matern52    k = σ² (1 + √5ρ + 5ρ²/3) e^{−√5ρ},  ρ² = Σ_d ((x_d − x'_d)/l_d)²  (paper eq. 8; P2)
 *   - rbf         k = σ² exp(−½ ρ²)                                               (P3)
 *   - ledergerber k = θ0 exp(−(1 − xᵀx'/(‖x‖‖x'‖))/θ1 − (‖x‖ − ‖x'‖)²/θ2), x ∈ ℝ³  (paper k_L, eq. 9; P4)
 *  A kernel is Σ_terms Π_{parts in term} k_part (P5). Presets `z1`, `z2`, `tdoa` are the paper's eq. 7–9.
 *
 *  Each part type is its own class (kernels/Parts.h), defined in its own file (src/gp/kernels/: Rbf, Matern52,
 *  Periodic, Ledergerber) with its value, analytic gradient and fast paths side by side; kernels/Product.h
 *  multiplies parts, this class sums the products and owns the parameters. The paper's compositions and the pair
 *  presets are named in kernels/Presets.h.
 *
 *  Design: a runtime composite over ONE flat vector of positive hyperparameters (values θ > 0, optimized in
 *  log-space: θ = exp(ξ), a smooth positive transform). Gram/cross matrices and their gradients are computed
 *  a whole block at a time with vectorized Eigen column operations, so there is no per-element virtual call.
 *  Points are ROWS of the input matrices (X is n×D).
 */
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "uwb/core/Types.h"
#include "uwb/gp/kernels/KernelPart.h"
#include "uwb/gp/kernels/Product.h"

namespace uwb::gp {

/// A named scalar hyperparameter (albatross-style): positive value, trainable or fixed.
struct Parameter {
  double value = 1.0;
  bool trainable = true;
};

/// Sum of products of parts over one flat positive parameter vector.
class Kernel {
 public:
  Kernel() = default;
  /// Σ_p part_p (every term has one part).
  static Kernel sum(const std::vector<PartSpec>& parts);
  /// Π_p part_p (one term).
  static Kernel product(const std::vector<PartSpec>& parts);
  /// General sum of products: terms[t] lists indices into parts.
  Kernel(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms);

  /// Paper presets on the bias-model feature columns (docs/math/gp.md P6):
  ///  "z1"  : periodic(col 0) + periodic(col 1), T = 2π fixed             (paper eq. 7)
  ///  "z2"  : matern52(col 0) + matern52(col 1)                           (paper eq. 8)
  ///  "tdoa": ledergerber(cols 0–2) + ledergerber(cols 3–5)               (paper eq. 9)
  static Kernel preset(const std::string& name);

  int inputDim() const { return input_dim_; }     ///< 1 + largest active column
  int numParams() const { return static_cast<int>(theta_.size()); }
  int numParts() const { return static_cast<int>(parts_.size()); }
  const std::vector<std::vector<int>>& terms() const { return terms_; }
  PartType partType(int p) const { return parts_[p]->type(); }
  const std::vector<int>& activeDims(int p) const { return parts_[p]->activeDims(); }
  std::string name() const;  ///< e.g. "(periodic[0]+periodic[1])"

  /// Positive parameter values θ (flat) and their names ("p0.periodic.sigma2", "p0.periodic.l[0]", ...).
  const VecX& theta() const { return theta_; }
  void setTheta(const VecX& theta);
  const std::vector<std::string>& paramNames() const { return names_; }
  const std::vector<bool>& trainable() const { return trainable_; }
  void setTrainable(const std::string& name, bool trainable);
  std::map<std::string, Parameter> params() const;
  void setParam(const std::string& name, double value);  ///< throws std::invalid_argument (unknown / ≤ 0)
  double param(const std::string& name) const;
  /// Parameters of part p as a PartSpec (current values).
  PartSpec partSpec(int p) const;

  /// k(x, x') for two single points (rows of length ≥ inputDim()).
  double operator()(const Eigen::Ref<const RowVecX>& x, const Eigen::Ref<const RowVecX>& xp) const;
  /// K(X1, X2): n1×n2. When `part_blocks` is non-null it receives each part's own matrix (for gradients).
  MatX cross(const MatX& X1, const MatX& X2, std::vector<MatX>* part_blocks = nullptr) const;
  /// k(X1_i, x) for every row i of X1 into out (size X1.rows()): the column K(X1, x) without heap allocation,
  /// vectorized in chunks of 64 rows (stack buffers). Used for single-point predictions.
  void crossColumn(const MatX& X1, const Eigen::Ref<const RowVecX>& x, Eigen::Ref<VecX> out) const;
  /// K(X1, X2) into a preallocated n1×n2 matrix, one column (row of X2) at a time: the batch-prediction path
  /// (docs/math/gp.md P32). No per-element calls: e^x by a vectorized polynomial (P32, ≤ 2 ulp), so it agrees with
  /// cross() to ~1e-15 relative rather than bit for bit; every row of X1 gets the same value wherever it sits in
  /// X1. Throws like cross() (too few columns, ledergerber input of zero norm).
  void crossInto(const MatX& X1, const MatX& X2, Eigen::Ref<MatX> K) const;
  /// K(X, X).
  MatX gram(const MatX& X) const { return cross(X, X); }
  /// k(x_n, x_n) for every row (no jitter). Every part type is stationary on its diagonal: k(x,x) = σ².
  VecX diag(const MatX& X) const;
  /// k(x, x) (the same for every x).
  double diagValue() const;

  /// Adds Σ_ij G_ij ∂k(x1_i, x2_j)/∂θ to grad_theta (size numParams(), values θ, not log θ) and, when
  /// grad_X1 is non-null, Σ_j G_ij ∂k(x1_i, x2_j)/∂x1_i to row i of grad_X1 (n1×D). `part_blocks` must be the
  /// blocks returned by cross(X1, X2, &part_blocks). docs/math/gp.md P7–P10.
  void accumulateCrossGradient(const MatX& X1, const MatX& X2, const MatX& G, const std::vector<MatX>& part_blocks,
                               VecX& grad_theta, MatX* grad_X1) const;
  /// Adds (Σ_n g_n) ∂k(x,x)/∂θ to grad_theta (the diagonal depends on the outputscales only).
  void accumulateDiagGradient(double sum_g, VecX& grad_theta) const;

  nlohmann::json toJson() const;
  static Kernel fromJson(const nlohmann::json& j);  ///< throws std::invalid_argument with a clear message

 private:
  void build(const std::vector<PartSpec>& parts, const std::vector<std::vector<int>>& terms);
  MatX partCross(int p, const MatX& X1, const MatX& X2) const;

  PartList parts_;                     ///< immutable, shared between copies
  std::vector<Product> products_;      ///< the terms
  std::vector<std::vector<int>> terms_;
  VecX theta_;
  std::vector<std::string> names_;
  std::vector<bool> trainable_;
  int input_dim_ = 0;
};

}  // namespace uwb::gp
