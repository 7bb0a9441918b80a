/** @file Nodes.h
 *  @brief Node rules of a Forney-style factor graph for Gaussian messages, one free function per table row of
 *         Loeliger, Dauwels, Hu, Korl, Ping, Kschischang, "The factor graph approach to model-based signal
 *         processing", Proc. IEEE 95(6), 2007, Tables 2–4 (docs/math/message-passing.md G3–G10).
 *
 *  Arrow convention: for a node with inputs X, Y and output Z, "forward" computes the message on Z from the
 *  messages on X and Y; "backward" computes the message on X from the messages on Z (and Y).
 *  All functions check dimensions and throw std::invalid_argument on a mismatch.
 */
#pragma once

#include <optional>

#include "uwb/graph/GaussianMessage.h"

namespace uwb {

/// (G3) Equality node X = Y = Z, information form (Table 2, equality constraint):
///      ξ_Z = ξ_X + ξ_Y,  W_Z = W_X + W_Y.  Works for singular W_X or W_Y.
Information equality(const Information& x, const Information& y);

/// (G4) Equality node with a moment-form message X and an information-form message Y (W_Y possibly singular),
///      the "Kalman-gain" variant that needs no inverse of V_X (Table 2 equality row rewritten with
///      (V_X⁻¹ + W_Y)⁻¹ = (I + V_X W_Y)⁻¹ V_X):
///      V_Z = (I + V_X W_Y)⁻¹ V_X,   m_Z = (I + V_X W_Y)⁻¹ (m_X + V_X ξ_Y).
///      nullopt only if (I + V_X W_Y) is numerically singular (cannot happen for V_X, W_Y ⪰ 0).
std::optional<Moments> equality(const Moments& x, const Information& y);

/// (G5) Equality node, moment form (Table 2): V_Z = V_X (V_X + V_Y)⁻¹ V_Y,
///      m_Z = m_X + V_X (V_X + V_Y)⁻¹ (m_Y − m_X). nullopt if V_X + V_Y is singular.
std::optional<Moments> equality(const Moments& x, const Moments& y);

/// (G6) Matrix multiplication node Y = A X, forward (Table 2): m_Y = A m_X,  V_Y = A V_X Aᵀ.
Moments multiplyForward(const MatX& A, const Moments& x);

/// (G7) Matrix multiplication node Y = A X, backward (Table 2): ξ_X = Aᵀ ξ_Y,  W_X = Aᵀ W_Y A.
Information multiplyBackward(const MatX& A, const Information& y);

/// (G8) Addition node Z = X + Y, forward (Table 2): m_Z = m_X + m_Y,  V_Z = V_X + V_Y.
Moments additionForward(const Moments& x, const Moments& y);

/// (G9) Addition node Z = X + Y, backward to X (Table 2): m_X = m_Z − m_Y,  V_X = V_Z + V_Y.
Moments additionBackward(const Moments& z, const Moments& y);

/// (G9') Addition of a known constant, Z = X + c, backward in information form:
///      ξ_X = ξ_Z − W_Z c,  W_X = W_Z  (G9 with V_Y = 0, written for possibly singular W_Z).
Information additionBackwardConstant(const Information& z, const VecX& c);

/// (G10) Composite block "equality node followed by multiplication node" in moment form (Table 4): the prior X
///      (moments), an observation Y = A Z with message N(m_Y, V_Y):
///      G = (V_Y + A V_X Aᵀ)⁻¹,  m_Z = m_X + V_X Aᵀ G (m_Y − A m_X),  V_Z = V_X − V_X Aᵀ G A V_X.
///      This is the Kalman update. nullopt if V_Y + A V_X Aᵀ is singular.
std::optional<Moments> equalityMultiply(const Moments& x, const MatX& A, const Moments& y);

}  // namespace uwb
