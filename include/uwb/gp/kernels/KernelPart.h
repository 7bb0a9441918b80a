/** @file KernelPart.h
 *  @brief One kernel part (docs/math/gp.md P1–P4): the interface every part type implements, with its value, its
 *         analytic gradient and its fast paths side by side in the part's own file (kernels/Rbf.h, Matern52.h,
 *         Periodic.h, Ledergerber.h). Parts are composed by products (kernels/Product.h) and sums (gp/Kernel.h).
 *
 *  A part holds no parameter values: they live in the kernel's one flat vector θ (values > 0), and a part knows
 *  where its own start (`offset`, the index of its outputscale σ²). A and B below are the part's ACTIVE columns of
 *  the inputs (points are rows).
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "uwb/core/Types.h"

namespace uwb::gp {

enum class PartType { kRbf, kMatern52, kPeriodic, kLedergerber };

std::string toString(PartType type);
PartType partTypeFromString(const std::string& name);  ///< throws std::invalid_argument

/// One kernel part. Parameters are given as positive values; sizes of `l` and `T` are 1 (shared) or the number
/// of active dims (ARD). Unused fields are ignored for the type (e.g. `l` for ledergerber).
struct PartSpec {
  PartType type = PartType::kRbf;
  std::vector<int> active_dims;   ///< columns of the input row this part reads, in order
  double sigma2 = 1.0;            ///< outputscale σ² (θ0 for ledergerber)
  std::vector<double> l{1.0};     ///< lengthscales (paper l; NOT GPyTorch's l² for periodic)
  std::vector<double> T{2.0 * kPi};  ///< periods (periodic only)
  double t1 = 1.0;                ///< ledergerber θ1 (angular scale, dimensionless)
  double t2 = 1.0;                ///< ledergerber θ2 (range scale) [m²]
  bool train_period = false;      ///< periodic: T trainable (paper: T = 2π fixed)
};

/// The flat parameter list a kernel is built into: each part appends its values with their names.
struct ParamList {
  std::vector<double> values;
  std::vector<std::string> names;
  std::vector<bool> trainable;
  /// Appends prefix + name = value; throws std::invalid_argument unless the value is positive and finite.
  void add(const std::string& prefix, const std::string& name, double value, bool train);
  /// Appends 1 shared value or one per active dimension (name[i]); returns how many.
  int addList(const std::string& prefix, const std::string& name, const std::vector<double>& v, int nd, bool train);
};

/// Rows of the one-point path (Kernel::crossColumn), on the stack: no allocation.
constexpr int kChunkRows = 64;
using Chunk = Eigen::Array<double, Eigen::Dynamic, 1, 0, kChunkRows, 1>;

/// What a part prepares once for a batch evaluation (Kernel::crossInto); each part type derives its own.
struct PreparedBlock {
  virtual ~PreparedBlock() = default;
};

class KernelPart {
 public:
  virtual ~KernelPart() = default;
  virtual PartType type() const = 0;
  const std::vector<int>& activeDims() const { return active_dims_; }
  Eigen::Index outputscaleIndex() const { return offset_; }  ///< θ index of σ² (θ0 for ledergerber)
  /// The part's parameters (current values θ) as a spec.
  virtual PartSpec spec(const VecX& theta, const std::vector<bool>& trainable) const = 0;

  /// k_p(A, B): the reference evaluation every other path is tested against.
  virtual MatX block(const MatX& A, const MatX& B, const VecX& theta) const = 0;
  /// Batch path (docs/math/gp.md P32): the active columns prepared once, then one column k_p(A, B_j) at a time,
  /// vectorized over the rows of A, into out (A.rows() values).
  virtual std::unique_ptr<PreparedBlock> prepare(MatX A, MatX B, const VecX& theta) const = 0;
  virtual void column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out) const = 0;
  /// One-point path: prod *= k_p(X1 rows i0 … i0 + prod.size() − 1, x) (full input rows, not active columns).
  virtual void multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,
                             Chunk& prod) const = 0;
  /// Gradient (docs/math/gp.md P7–P10) of Σ_ij H_ij k_p(a_i, b_j) w.r.t. the part's parameters other than σ² (the
  /// caller adds ∂/∂σ² = Σ W / σ²) into grad_theta and, when non-null, w.r.t. a_i into grad_X1's active columns.
  /// W = H ∘ K_p.
  virtual void accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX& W, const VecX& theta,
                                  VecX& grad_theta, MatX* grad_X1) const = 0;

 protected:
  KernelPart(std::vector<int> active_dims, int offset) : active_dims_(std::move(active_dims)), offset_(offset) {}
  std::vector<int> active_dims_;
  int offset_ = 0;
};

/// The overrides every part type declares; each part's own file defines them (kernels/Rbf.cpp, ...).
#define UWB_KERNEL_PART_OVERRIDES                                                                                    \
  PartSpec spec(const VecX& theta, const std::vector<bool>& trainable) const override;                             \
  MatX block(const MatX& A, const MatX& B, const VecX& theta) const override;                                      \
  std::unique_ptr<PreparedBlock> prepare(MatX A, MatX B, const VecX& theta) const override;                        \
  void column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out) const override;       \
  void multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,        \
                     Chunk& prod) const override;                                                                  \
  void accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX& W, const VecX& theta,           \
                          VecX& grad_theta, MatX* grad_X1) const override;

/// Shared by the parts with lengthscales (rbf, matern52, periodic): σ² at offset, then n_l lengthscales.
class LengthscalePart : public KernelPart {
 protected:
  /// Appends sigma2 and l (1 or one per active dim) to params.
  LengthscalePart(const PartSpec& spec, const std::string& prefix, ParamList& params);
  /// θ index of the lengthscale of active dimension d (one shared, or one per dimension).
  Eigen::Index lengthscaleIndex(Eigen::Index d) const { return offset_ + 1 + (n_l_ == 1 ? 0 : d); }
  /// σ² and l of the spec.
  PartSpec lengthscaleSpec(const VecX& theta) const;
  /// ρ² = Σ_d ((a_d − b_d)/l_d)² for every pair (P2, P3).
  MatX scaledSquaredDistance(const MatX& A, const MatX& B, const VecX& theta) const;
  /// A and B with each column divided by its lengthscale (the batch path's ρ² = Σ_d (a_d/l_d − b_d/l_d)²).
  void divideByLengthscales(MatX& A, MatX& B, const VecX& theta) const;
  /// Σ_d ((x1_d − x_d)/l_d)² over a chunk of rows (the one-point path).
  Chunk chunkSquaredDistance(const MatX& X1, Eigen::Index i0, Eigen::Index c, const Eigen::Ref<const RowVecX>& x,
                             const VecX& theta) const;
  /// The lengthscale and input gradients of a radial part, with w the weight in ∂k/∂x_d = −w Δ_d / l_d² and
  /// ∂k/∂l_d = w Δ_d² / l_d³ (P8, P9).
  void accumulateRadialGradient(const MatX& A, const MatX& B, const MatX& Wg, const VecX& theta, VecX& grad_theta,
                                MatX* grad_X1) const;
  int n_l_ = 1;
};

/// The active columns of X, as an n×d matrix.
MatX activeColumns(const MatX& X, const std::vector<int>& dims);

/// The part of spec.type; its parameters are appended to params, named "p<index>.<type>.<name>".
std::unique_ptr<const KernelPart> makePart(const PartSpec& spec, int index, ParamList& params);
/// The part's parameters in the model file (our layout; FIXTURES.md §2 for the fixtures' "paper" block).
void partSpecToJson(const PartSpec& spec, nlohmann::json& jp);
/// Reads them back: `src` holds the parameter values, `jp` the part's own fields.
void partSpecFromJson(const nlohmann::json& src, const nlohmann::json& jp, PartSpec& spec);

}  // namespace uwb::gp
