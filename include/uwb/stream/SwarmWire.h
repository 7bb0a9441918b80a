/** @file SwarmWire.h
 *  @brief The ZeroMQ messages of `uwbtdoa swarm` (docs/io.md §7, swarm wire version 1). Every message is two
 *         frames, topic and body text:
 *
 *    "uwb.swarm.v1.events.KKKK"  agent KKKK's sensor events: "# SEND_NS" then event lines (LineProtocol.h) and
 *                                "twr,t,peer,range_m" lines, '\n'-separated; "# end" closes the stream
 *    "uwb.swarm.v1.belief"       "belief,agent,t,send_ns,m×3,Σ upper×6,v×3,Σv diagonal×3" (G22)
 *    "uwb.swarm.v1.estimate"     "est,agent,t,p_coop×3,Σ_coop upper×6,p_indep×3,Σ_indep upper×6"
 *    "uwb.swarm.v1.done"         one JSON object: the agent's counts and latency quantiles
 *
 *  Numbers are written with the shortest text that reads back to the same double. Upper triangles are row-major
 *  (00, 01, 02, 11, 12, 22).
 */
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "uwb/eval/SwarmLocalization.h"

namespace uwb {

inline constexpr std::string_view kSwarmEventTopicPrefix = "uwb.swarm.v1.events.";
inline constexpr std::string_view kSwarmBeliefTopic = "uwb.swarm.v1.belief";
inline constexpr std::string_view kSwarmEstimateTopic = "uwb.swarm.v1.estimate";
inline constexpr std::string_view kSwarmDoneTopic = "uwb.swarm.v1.done";

/// "uwb.swarm.v1.events.0007" (fixed width: no agent's topic is a prefix of another's).
std::string swarmEventTopic(int agent);

/// One TWR event line.
std::string formatTwrLine(double t_s, int peer, double range_m);
/// True when `line` is a TWR line; then fills the fields. Throws InputError naming line_no and the field when
/// a "twr," line is malformed.
bool parseTwrLine(std::string_view line, std::size_t line_no, double* t_s, int* peer, double* range_m);

std::string formatBelief(const NeighbourBelief& b, std::int64_t send_ns);
NeighbourBelief parseBelief(std::string_view line, std::size_t message_no, std::int64_t* send_ns = nullptr);

/// One collected estimate pair.
struct SwarmEstimate {
  int agent = 0;
  double t_s = 0.0;
  Vec3 p_coop = Vec3::Zero(), p_indep = Vec3::Zero();
  Mat3 cov_coop = Mat3::Zero(), cov_indep = Mat3::Zero();
};
std::string formatSwarmEstimate(const SwarmEstimate& e);
SwarmEstimate parseSwarmEstimate(std::string_view line, std::size_t message_no);

}  // namespace uwb
