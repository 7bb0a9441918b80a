/** @file AnchorSurvey.cpp */
#include "uwb/io/AnchorSurvey.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace uwb {

bool AnchorSurvey::contains(int id) const {
  return std::any_of(anchors.begin(), anchors.end(), [id](const Anchor& a) { return a.id == id; });
}

const Anchor& AnchorSurvey::at(int id) const {
  for (const Anchor& a : anchors) {
    if (a.id == id) return a;
  }
  throw std::out_of_range("anchor id " + std::to_string(id) + " has no entry in the survey" +
                          (source.empty() ? std::string() : " " + source));
}

}  // namespace uwb
