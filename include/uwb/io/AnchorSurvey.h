/** @file AnchorSurvey.h
 *  @brief Surveyed UWB anchors (UTIL survey text: `an{i}_p,x,y,z` and `an{i}_quat,qx,qy,qz,qw`).
 */
#pragma once

#include <string>
#include <vector>

#include "uwb/core/Types.h"

namespace uwb {

/// Largest anchor id the readers accept (Loco Positioning anchors carry an 8-bit id). Tables indexed by id stay
/// small; a file with id 2147483647 is refused with its line instead of allocating gigabytes.
inline constexpr int kMaxAnchorId = 255;

struct Anchor {
  int id = 0;
  Vec3 w_p = Vec3::Zero();        ///< anchor antenna position in the world (Vicon) frame [m]
  Quat w_q = Quat::Identity();    ///< anchor orientation (informational)
};

/// A set of anchors addressed by id. Ids need not be contiguous.
struct AnchorSurvey {
  std::vector<Anchor> anchors;  ///< sorted by id
  std::string source;           ///< file it came from, for messages

  bool contains(int id) const;
  /// Throws std::out_of_range naming the id and the survey source when absent.
  const Anchor& at(int id) const;
  const Vec3& position(int id) const { return at(id).w_p; }
};

}  // namespace uwb
