/** @file Product.cpp
 *  @brief Products of kernel parts (docs/math/gp.md P5).
 */
#include "uwb/gp/kernels/Product.h"

namespace uwb::gp {

double Product::diagValue(const PartList& parts, const VecX& theta) const {
  double prod = 1.0;
  for (int p : factors_) prod *= theta[parts[p]->outputscaleIndex()];
  return prod;
}

void Product::accumulateDiagGradient(const PartList& parts, const VecX& theta, double sum_g, VecX& grad_theta) const {
  for (int p : factors_) {
    double others = 1.0;
    for (int q : factors_)
      if (q != p) others *= theta[parts[q]->outputscaleIndex()];
    grad_theta[parts[p]->outputscaleIndex()] += sum_g * others;  // ∂k(x,x)/∂σ²_p = Π_{q≠p} σ²_q
  }
}

MatX Product::block(const PartList& parts, const MatX& X1, const MatX& X2, const VecX& theta,
                    std::vector<MatX>* part_blocks) const {
  MatX prod;
  for (std::size_t i = 0; i < factors_.size(); ++i) {
    const KernelPart& part = *parts[factors_[i]];
    MatX Kp = part.block(activeColumns(X1, part.activeDims()), activeColumns(X2, part.activeDims()), theta);
    if (i == 0)
      prod = Kp;
    else
      prod.array() *= Kp.array();
    if (part_blocks) (*part_blocks)[factors_[i]] = std::move(Kp);
  }
  return prod;
}

void Product::column(const PartList& parts, const std::vector<std::unique_ptr<PreparedBlock>>& prepared,
                     Eigen::Index j, const VecX& theta, double* dst, Eigen::ArrayXd& part_scratch) const {
  parts[factors_[0]]->column(*prepared[factors_[0]], j, theta, dst);
  Eigen::Map<Eigen::ArrayXd> prod(dst, part_scratch.size());
  for (std::size_t i = 1; i < factors_.size(); ++i) {
    parts[factors_[i]]->column(*prepared[factors_[i]], j, theta, part_scratch.data());
    prod *= part_scratch;
  }
}

void Product::multiplyChunk(const PartList& parts, const MatX& X1, Eigen::Index i0,
                            const Eigen::Ref<const RowVecX>& x, const VecX& theta, Chunk& prod) const {
  for (int p : factors_) parts[p]->multiplyChunk(X1, i0, x, theta, prod);
}

void Product::accumulateGradient(const PartList& parts, const MatX& X1, const MatX& X2, const MatX& G,
                                 const std::vector<MatX>& part_blocks, const VecX& theta, VecX& grad_theta,
                                 MatX* grad_X1) const {
  auto partGradient = [&](int p, const MatX& H) {
    const KernelPart& part = *parts[p];
    const MatX A = activeColumns(X1, part.activeDims());
    const MatX B = activeColumns(X2, part.activeDims());
    const Eigen::Index s2_index = part.outputscaleIndex();
    const MatX W = H.cwiseProduct(part_blocks[p]);  // H ∘ k
    const double sumW = W.sum();
    grad_theta[s2_index] += sumW / theta[s2_index];  // ∂k/∂σ² = k/σ²
    part.accumulateGradient(A, B, H, W, theta, grad_theta, grad_X1);
  };
  for (int p : factors_) {
    if (factors_.size() == 1) {
      partGradient(p, G);
    } else {
      MatX H = G;  // P5: ∂(Π k_q)/∂θ_p = (Π_{q≠p} k_q) ∂k_p/∂θ_p
      for (int q : factors_)
        if (q != p) H.array() *= part_blocks[q].array();
      partGradient(p, H);
    }
  }
}

}  // namespace uwb::gp
