/** @file PredictTile.cpp
 *  @brief docs/math/gp.md (P33): the fused mean / kᵀQ_u k tile, AVX2 and plain reference, and the Q_u packing.
 */
#include "uwb/gp/PredictTile.h"

#include <algorithm>
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace uwb::gp {

std::vector<double> packQuPanels(const MatX& Q) {
  const Eigen::Index M = Q.rows();
  std::vector<double> qpack;
  for (Eigen::Index l0 = 0; l0 < M; l0 += kQuPanel) {
    const Eigen::Index jend = std::min(l0 + kQuPanel, M);
    for (Eigen::Index j = 0; j < jend; ++j) {
      for (Eigen::Index c = 0; c < kQuPanel; ++c) {
        const Eigen::Index l = l0 + c;
        qpack.push_back(l >= M || j > l ? 0.0 : (j == l ? Q(j, l) : 2.0 * Q(j, l)));
      }
    }
  }
  return qpack;
}

void tileMeanQuadFormReference(const double* K, Eigen::Index ld, Eigen::Index M, const double* qpack,
                               const double* alpha, double* mean, double* var) {
  // The arithmetic of the AVX2 version with plain multiply-adds (each lane i is one point).
  double m[4][kTilePoints] = {};
  Eigen::Index j = 0;
  for (; j + 4 <= M; j += 4)
    for (int r = 0; r < 4; ++r)
      for (int i = 0; i < kTilePoints; ++i) m[r][i] += K[(j + r) * ld + i] * alpha[j + r];
  for (int r = 0; j < M; ++j, ++r)
    for (int i = 0; i < kTilePoints; ++i) m[r][i] += K[j * ld + i] * alpha[j];
  for (int i = 0; i < kTilePoints; ++i) mean[i] = (m[0][i] + m[1][i]) + (m[2][i] + m[3][i]);
  if (!var) return;
  double v[kTilePoints] = {};
  const double* q = qpack;
  for (Eigen::Index l0 = 0; l0 < M; l0 += kQuPanel) {
    const Eigen::Index jend = std::min(l0 + kQuPanel, M);
    double t[kQuPanel][kTilePoints] = {};
    for (Eigen::Index jj = 0; jj < jend; ++jj, q += kQuPanel)
      for (int c = 0; c < kQuPanel; ++c)
        for (int i = 0; i < kTilePoints; ++i) t[c][i] += K[jj * ld + i] * q[c];
    for (int c = 0; c < kQuPanel; ++c) {
      const double* kc = K + std::min<Eigen::Index>(l0 + c, M - 1) * ld;
      for (int i = 0; i < kTilePoints; ++i) v[i] += t[c][i] * kc[i];
    }
  }
  for (int i = 0; i < kTilePoints; ++i) var[i] = v[i];
}

#if defined(__AVX2__) && defined(__FMA__)
namespace {
void tileMeanQuadFormAvx2(const double* K, Eigen::Index ld, Eigen::Index M, const double* qpack, const double* alpha,
                          double* mean, double* var) {
  {  // mean: 4 partial sums per half (j mod 4), added at the end
    __m256d m0[4], m1[4];
    for (int r = 0; r < 4; ++r) m0[r] = m1[r] = _mm256_setzero_pd();
    Eigen::Index j = 0;
    for (; j + 4 <= M; j += 4) {
#pragma GCC unroll 4
      for (int r = 0; r < 4; ++r) {
        const __m256d a = _mm256_broadcast_sd(alpha + j + r);
        m0[r] = _mm256_fmadd_pd(_mm256_loadu_pd(K + (j + r) * ld), a, m0[r]);
        m1[r] = _mm256_fmadd_pd(_mm256_loadu_pd(K + (j + r) * ld + 4), a, m1[r]);
      }
    }
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) {  // constant indices keep the partial sums in registers
      if (j + r < M) {
        const __m256d a = _mm256_broadcast_sd(alpha + j + r);
        m0[r] = _mm256_fmadd_pd(_mm256_loadu_pd(K + (j + r) * ld), a, m0[r]);
        m1[r] = _mm256_fmadd_pd(_mm256_loadu_pd(K + (j + r) * ld + 4), a, m1[r]);
      }
    }
    _mm256_storeu_pd(mean, _mm256_add_pd(_mm256_add_pd(m0[0], m0[1]), _mm256_add_pd(m0[2], m0[3])));
    _mm256_storeu_pd(mean + 4, _mm256_add_pd(_mm256_add_pd(m1[0], m1[1]), _mm256_add_pd(m1[2], m1[3])));
  }
  if (!var) return;
  __m256d v0 = _mm256_setzero_pd(), v1 = _mm256_setzero_pd();
  const double* q = qpack;
  for (Eigen::Index l0 = 0; l0 < M; l0 += kQuPanel) {
    const Eigen::Index jend = std::min(l0 + kQuPanel, M);
    __m256d t0[kQuPanel], t1[kQuPanel];
#pragma GCC unroll 6
    for (int c = 0; c < kQuPanel; ++c) t0[c] = t1[c] = _mm256_setzero_pd();
    for (Eigen::Index j = 0; j < jend; ++j, q += kQuPanel) {
      const __m256d k0 = _mm256_loadu_pd(K + j * ld), k1 = _mm256_loadu_pd(K + j * ld + 4);
#pragma GCC unroll 6
      for (int c = 0; c < kQuPanel; ++c) {
        const __m256d qc = _mm256_broadcast_sd(q + c);
        t0[c] = _mm256_fmadd_pd(k0, qc, t0[c]);
        t1[c] = _mm256_fmadd_pd(k1, qc, t1[c]);
      }
    }
    // constant c (registers stay registers); past column M − 1, t is 0 and any column may be read: take M − 1
#pragma GCC unroll 6
    for (int c = 0; c < kQuPanel; ++c) {
      const double* kc = K + std::min<Eigen::Index>(l0 + c, M - 1) * ld;
      v0 = _mm256_fmadd_pd(t0[c], _mm256_loadu_pd(kc), v0);
      v1 = _mm256_fmadd_pd(t1[c], _mm256_loadu_pd(kc + 4), v1);
    }
  }
  _mm256_storeu_pd(var, v0);
  _mm256_storeu_pd(var + 4, v1);
}
}  // namespace
#endif

void tileMeanQuadForm(const double* K, Eigen::Index ld, Eigen::Index M, const double* qpack, const double* alpha,
                      double* mean, double* var) {
#if defined(__AVX2__) && defined(__FMA__)
  tileMeanQuadFormAvx2(K, ld, M, qpack, alpha, mean, var);
#else
  tileMeanQuadFormReference(K, ld, M, qpack, alpha, mean, var);
#endif
}

bool tileMeanQuadFormIsVectorized() {
#if defined(__AVX2__) && defined(__FMA__)
  return true;
#else
  return false;
#endif
}

}  // namespace uwb::gp
