/** @file Matern52.cpp
 *  @brief The Matérn-5/2 part: value (P2), gradient (P9), batch column (P32), one-point chunk.
 */
#include "uwb/gp/kernels/Parts.h"

#include "ScaledExp.h"

namespace uwb::gp {

namespace {

constexpr double kSqrt5 = 2.23606797749978969640917366873128;

/// (P2) Matérn-5/2 polynomial 1 + √5ρ + 5ρ²/3, in terms of r = √5ρ: k = σ² (1 + r + r²/3) e^{−r}.
template <class R>
auto matern52Polynomial(const R& r) {
  return 1.0 + r + r.square() / 3.0;
}

struct Matern52Prepared final : PreparedBlock {
  MatX A, B;                         ///< active columns divided by l
  mutable Eigen::ArrayXd scratch;   ///< √5ρ of the current column
};

}  // namespace

Matern52Part::Matern52Part(const PartSpec& spec, const std::string& prefix, ParamList& params)
    : LengthscalePart(spec, prefix, params) {}

PartSpec Matern52Part::spec(const VecX& theta, const std::vector<bool>&) const { return lengthscaleSpec(theta); }

MatX Matern52Part::block(const MatX& A, const MatX& B, const VecX& theta) const {
  MatX K = scaledSquaredDistance(A, B, theta);           // ρ² (P2)
  const Eigen::ArrayXXd r = K.array().sqrt() * kSqrt5;  // √5 ρ
  K = theta[offset_] * matern52Polynomial(r) * (-r).exp();
  return K;
}

std::unique_ptr<PreparedBlock> Matern52Part::prepare(MatX A, MatX B, const VecX& theta) const {
  auto q = std::make_unique<Matern52Prepared>();
  q->A = std::move(A);
  q->B = std::move(B);
  divideByLengthscales(q->A, q->B, theta);
  q->scratch.resize(q->A.rows());
  return q;
}

void Matern52Part::column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out_data) const {
  const auto& q = static_cast<const Matern52Prepared&>(prepared);
  const Eigen::Index n1 = q.A.rows(), nd = q.A.cols();
  Eigen::Map<Eigen::ArrayXd> out(out_data, n1);
  // ρ² = Σ_d (a_d/l_d − b_d/l_d)²  (P2)
  out = (q.A.col(0).array() - q.B(j, 0)).square();
  for (Eigen::Index d = 1; d < nd; ++d) out += (q.A.col(d).array() - q.B(j, d)).square();
  q.scratch = out.sqrt() * kSqrt5;  // √5 ρ
  out = q.scratch;
  detail::scaledExpInPlace(out.data(), n1, -1.0, 1.0);
  out *= theta[offset_] * matern52Polynomial(q.scratch);
}

void Matern52Part::multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x,
                                 const VecX& theta, Chunk& prod) const {
  const Chunk acc = chunkSquaredDistance(X1, i0, prod.size(), x, theta);
  const Chunk r = acc.sqrt() * kSqrt5;
  prod *= theta[offset_] * matern52Polynomial(r) * (-r).exp();
}

void Matern52Part::accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX&, const VecX& theta,
                                      VecX& grad_theta, MatX* grad_X1) const {
  // P9: Matérn-5/2, g = (5/3) σ² (1 + √5ρ) e^{−√5ρ}
  const Eigen::Index n2 = B.rows(), nd = A.cols();
  MatX R2 = MatX::Zero(A.rows(), n2);
  for (Eigen::Index d = 0; d < nd; ++d) {
    const double l = theta[lengthscaleIndex(d)];
    for (Eigen::Index j = 0; j < n2; ++j) R2.col(j).array() += ((A.col(d).array() - B(j, d)) / l).square();
  }
  const Eigen::ArrayXXd r = R2.array().sqrt() * kSqrt5;
  const MatX Wg = H.array() * ((5.0 / 3.0) * theta[offset_] * (1.0 + r) * (-r).exp());
  accumulateRadialGradient(A, B, Wg, theta, grad_theta, grad_X1);
}

}  // namespace uwb::gp
