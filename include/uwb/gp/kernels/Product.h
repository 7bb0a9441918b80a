/** @file Product.h
 *  @brief A product of kernel parts, Π_p k_p (docs/math/gp.md P5): its value in each evaluation path, its diagonal
 *         and its gradient by the product rule. A kernel (gp/Kernel.h) is a sum of products.
 */
#pragma once

#include <memory>
#include <vector>

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

using PartList = std::vector<std::shared_ptr<const KernelPart>>;

class Product {
 public:
  /// `factors`: indices into the kernel's parts (at least one).
  explicit Product(std::vector<int> factors) : factors_(std::move(factors)) {}
  const std::vector<int>& factors() const { return factors_; }

  /// k(x, x) = Π_p σ²_p: every part is stationary on its diagonal.
  double diagValue(const PartList& parts, const VecX& theta) const;
  /// Adds sum_g ∂k(x,x)/∂σ²_p = sum_g Π_{q≠p} σ²_q for every factor p.
  void accumulateDiagGradient(const PartList& parts, const VecX& theta, double sum_g, VecX& grad_theta) const;
  /// The block Π_p K_p(X1, X2) (the reference path); each factor's own block into part_blocks when non-null.
  MatX block(const PartList& parts, const MatX& X1, const MatX& X2, const VecX& theta,
             std::vector<MatX>* part_blocks) const;
  /// Column j of the block into dst (n1 values) from the factors' prepared data; part_scratch holds n1 values.
  void column(const PartList& parts, const std::vector<std::unique_ptr<PreparedBlock>>& prepared, Eigen::Index j,
              const VecX& theta, double* dst, Eigen::ArrayXd& part_scratch) const;
  /// prod *= the product over a chunk of rows of X1 against x.
  void multiplyChunk(const PartList& parts, const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x,
                     const VecX& theta, Chunk& prod) const;
  /// Adds Σ_ij G_ij ∂k/∂θ (and ∂k/∂x1_i) by the product rule: ∂(Π k_q)/∂θ_p = (Π_{q≠p} k_q) ∂k_p/∂θ_p (P5, P7–P10).
  void accumulateGradient(const PartList& parts, const MatX& X1, const MatX& X2, const MatX& G,
                          const std::vector<MatX>& part_blocks, const VecX& theta, VecX& grad_theta,
                          MatX* grad_X1) const;

 private:
  std::vector<int> factors_;
};

}  // namespace uwb::gp
