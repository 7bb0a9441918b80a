/** @file GaussianMessage.h
 *  @brief Gaussian messages of a Forney-style factor graph in moment form (m, V) and information form
 *         (ξ = W m, W = V⁻¹), with conversions (paper II-B; Loeliger et al. 2007; docs/math/message-passing.md G1–G2).
 *
 *  The parameterisation is part of the type; conversion happens only on request. Fixed-size variants
 *  (N = 3 for positions, N = 15 for the filter's error state) avoid heap allocation.
 */
#pragma once

#include <optional>
#include <variant>

#include "uwb/core/Types.h"

namespace uwb {

/// Moment form N(m, V): mean m and covariance V.
template <int N = Eigen::Dynamic>
struct GaussianMoments {
  Eigen::Matrix<double, N, 1> m;
  Eigen::Matrix<double, N, N> V;
};

/// Information form: weighted mean ξ = W m and information (precision) matrix W = V⁻¹. W may be singular
/// (a message that constrains only a subspace, e.g. one TDoA on a 3-D position).
template <int N = Eigen::Dynamic>
struct GaussianInformation {
  Eigen::Matrix<double, N, 1> xi;
  Eigen::Matrix<double, N, N> W;
};

using Moments = GaussianMoments<Eigen::Dynamic>;
using Information = GaussianInformation<Eigen::Dynamic>;
using Moments3 = GaussianMoments<3>;  ///< e.g. an anchor or agent position [m], covariance [m²]
using Information3 = GaussianInformation<3>;

/// A message travelling along an edge, in whichever form the sending node produced.
using GaussianMessage = std::variant<Moments, Information>;

/// (G1) W = V⁻¹, ξ = W m. nullopt when V is not positive definite (Cholesky fails).
std::optional<Information> toInformation(const Moments& x);
/// (G2) V = W⁻¹, m = V ξ. nullopt when W is not positive definite (singular information: no moment form).
std::optional<Moments> toMoments(const Information& x);
/// Either form → moments / information (identity when already in that form).
std::optional<Moments> asMoments(const GaussianMessage& msg);
std::optional<Information> asInformation(const GaussianMessage& msg);

}  // namespace uwb
