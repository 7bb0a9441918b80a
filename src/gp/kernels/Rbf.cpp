/** @file Rbf.cpp
 *  @brief The RBF part: value (P3), gradient (P8), batch column in one pass with e^x of P32, one-point chunk.
 */
#include "uwb/gp/kernels/Parts.h"

#include "ScaledExp.h"

namespace uwb::gp {

using detail::ScaledExpCoefs;

namespace {

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
    detail::scaledExpPackets<kP>(x, cf);
    for (int u = 0; u < kP; ++u) _mm256_storeu_pd(out + i + 4 * u, x[u]);
  }
  for (; i + 4 <= n; i += 4) {
    __m256d x = halfSqDist(i);
    detail::scaledExpPackets<1>(&x, cf);
    _mm256_storeu_pd(out + i, x);
  }
#endif
  for (; i < n; ++i) {
    double diff = A(i, 0) - b[0];
    double r2 = diff * diff;
    for (Eigen::Index d = 1; d < nd; ++d) {
      diff = A(i, d) - b[d];
      r2 = detail::fmaS(diff, diff, r2);
    }
    out[i] = detail::scaledExpScalar(-0.5 * r2, cf);
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

struct RbfPrepared final : PreparedBlock {
  MatX A;   ///< active columns of X1 divided by l
  MatX Bt;  ///< (active columns of X2 divided by l)ᵀ: row j of B contiguous
  ScaledExpCoefs cf{1.0};  ///< σ² p_i (P32)
};

}  // namespace

RbfPart::RbfPart(const PartSpec& spec, const std::string& prefix, ParamList& params)
    : LengthscalePart(spec, prefix, params) {}

PartSpec RbfPart::spec(const VecX& theta, const std::vector<bool>&) const { return lengthscaleSpec(theta); }

MatX RbfPart::block(const MatX& A, const MatX& B, const VecX& theta) const {
  MatX K = scaledSquaredDistance(A, B, theta);  // ρ² (P3)
  K = theta[offset_] * (-0.5 * K.array()).exp();
  return K;
}

std::unique_ptr<PreparedBlock> RbfPart::prepare(MatX A, MatX B, const VecX& theta) const {
  auto q = std::make_unique<RbfPrepared>();
  q->A = std::move(A);
  divideByLengthscales(q->A, B, theta);
  q->Bt = B.transpose();
  q->cf = ScaledExpCoefs(theta[offset_]);
  return q;
}

void RbfPart::column(const PreparedBlock& prepared, Eigen::Index j, const VecX&, double* out) const {
  const auto& q = static_cast<const RbfPrepared&>(prepared);
  rbfColumn(q.A, q.Bt.col(j).data(), q.cf, out);
}

void RbfPart::multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,
                            Chunk& prod) const {
  const Chunk acc = chunkSquaredDistance(X1, i0, prod.size(), x, theta);
  prod *= theta[offset_] * (-0.5 * acc).exp();
}

void RbfPart::accumulateGradient(const MatX& A, const MatX& B, const MatX&, const MatX& W, const VecX& theta,
                                 VecX& grad_theta, MatX* grad_X1) const {
  accumulateRadialGradient(A, B, W, theta, grad_theta, grad_X1);  // P8: w = H ∘ k
}

}  // namespace uwb::gp
