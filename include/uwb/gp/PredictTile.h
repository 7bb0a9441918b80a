/** @file PredictTile.h
 *  @brief The fused mean and quadratic form of the batch predictor (docs/math/gp.md P33): the hand-vectorized AVX2
 *         kernel and its plain C++ reference side by side, the packing of Q_u they read, and the 64-byte aligned
 *         buffer of the kernel block. SvgpPredictor calls tileMeanQuadForm; the tests compare both versions.
 */
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <new>
#include <vector>

#include "uwb/core/Types.h"

namespace uwb::gp {

inline constexpr Eigen::Index kTilePoints = 8;  ///< points per fused quadratic-form tile (P33): two AVX2 registers
inline constexpr Eigen::Index kQuPanel = 6;     ///< columns of Q_u per panel (P33): 6 × 2 accumulator registers

/// Q_u = triu(Q) with the off-diagonal doubled (kᵀQk = kᵀQ_u k, P20), cut into panels of kQuPanel columns; panel l0
/// holds rows j < min(l0 + kQuPanel, M) of kQuPanel values each (zeros below the diagonal and past column M − 1).
std::vector<double> packQuPanels(const MatX& Q);

/// docs/math/gp.md (P33): mean and kᵀQ_u k for the kTilePoints points whose kernel values are
/// K[j·ld + 0..7], j < M (one column of the column-major kernel block per inducing point):
///   mean_i = Σ_j k_ij α_j,   var_i = Σ_l k_il t_il,   t_il = Σ_{j≤l} k_ij (Q_u)_jl,
/// with t computed for a panel of kQuPanel columns l in registers (12 accumulators: 8 points × 6 columns) and
/// folded into var at once, so K Q_u is never stored. `qpack` holds the panels one after the other, each as rows
/// j = 0 … min(l0 + kQuPanel, M) − 1 of kQuPanel values (zeros below the diagonal and past column M − 1). Each
/// point's value is computed in its own lane by the same sequence of operations, so it does not depend on the
/// other points of the tile.
/// The vectorized version where the build has AVX2 and FMA, else the reference.
void tileMeanQuadForm(const double* K, Eigen::Index ld, Eigen::Index M, const double* qpack, const double* alpha,
                      double* mean, double* var);
/// The plain C++ reference: the same arithmetic with scalar multiply-adds, compiled in every build.
void tileMeanQuadFormReference(const double* K, Eigen::Index ld, Eigen::Index M, const double* qpack,
                               const double* alpha, double* mean, double* var);
/// True when tileMeanQuadForm runs the AVX2 version (the build has -mavx2 -mfma, e.g. UWB_NATIVE=ON).
bool tileMeanQuadFormIsVectorized();

/// An uninitialised array of doubles whose first element is 64-byte aligned (a tile's column is one cache line).
class AlignedDoubles {
 public:
  explicit AlignedDoubles(std::size_t n)
      : data_(static_cast<double*>(::operator new[](n * sizeof(double), std::align_val_t{64}))) {}
  double* data() { return data_.get(); }

 private:
  struct Free {
    void operator()(double* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<double[], Free> data_;
};

}  // namespace uwb::gp
