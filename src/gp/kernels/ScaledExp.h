/** @file ScaledExp.h
 *  @brief s·e^x for the kernels' batch path: docs/math/gp.md (P32). Private to src/gp/kernels.
 *
 *  e^x = 2^k e^r, k = round(x log₂e) (by adding 1.5·2⁵², which leaves k in the low mantissa bits), r = x − k ln2 in
 *  two FMA steps (fdlibm's split of ln2: k·ln2_hi is exact), e^r by a degree-11 polynomial: the Taylor series to
 *  degree 14 economized with Chebyshev polynomials on |r| ≤ 0.347 (≥ ln2/2), max relative error 1.3e-17 in exact
 *  arithmetic with these double coefficients (derivation: docs/math/gp.md P32), 2^k by writing k + 1023 into the
 *  exponent field. x is clamped to ≤ 709 (no overflow); x < −708 (e^x < 3.3e-308) gives 0; NaN stays NaN. The
 *  vector and scalar versions perform the same correctly rounded operations, so a value does not depend on which
 *  of them computed it.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "uwb/core/Types.h"
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace uwb::gp::detail {

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
inline void scaledExpInPlace(double* v, Eigen::Index n, double c, double s) {
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

}  // namespace uwb::gp::detail
