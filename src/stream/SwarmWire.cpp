/** @file SwarmWire.cpp
 *  @brief Text bodies of the swarm wire, version 1 (docs/io.md §7).
 */
#include "uwb/stream/SwarmWire.h"

#include <fmt/format.h>

#include <charconv>
#include <vector>

#include "uwb/core/Error.h"

namespace uwb {
namespace {

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> f;
  std::size_t start = 0;
  while (true) {
    const std::size_t c = line.find(',', start);
    f.push_back(line.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start));
    if (c == std::string_view::npos) break;
    start = c + 1;
  }
  return f;
}

double number(std::string_view s, std::size_t no, std::size_t col, const char* src, const char* field) {
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
    throw InputError(SourceLocation{src, no, col, field}, "'" + std::string(s) + "' is not a finite number");
  return v;
}

std::int64_t integer(std::string_view s, std::size_t no, std::size_t col, const char* src, const char* field) {
  std::int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size())
    throw InputError(SourceLocation{src, no, col, field}, "'" + std::string(s) + "' is not an integer");
  return v;
}

void appendUpper(std::string& out, const Mat3& V) {
  fmt::format_to(std::back_inserter(out), ",{},{},{},{},{},{}", V(0, 0), V(0, 1), V(0, 2), V(1, 1), V(1, 2), V(2, 2));
}

Mat3 readUpper(const std::vector<std::string_view>& f, std::size_t i0, std::size_t no, const char* src) {
  Mat3 V;
  const double u[6] = {number(f[i0], no, i0 + 1, src, "cov"),     number(f[i0 + 1], no, i0 + 2, src, "cov"),
                       number(f[i0 + 2], no, i0 + 3, src, "cov"), number(f[i0 + 3], no, i0 + 4, src, "cov"),
                       number(f[i0 + 4], no, i0 + 5, src, "cov"), number(f[i0 + 5], no, i0 + 6, src, "cov")};
  V << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
  return V;
}

Vec3 read3(const std::vector<std::string_view>& f, std::size_t i0, std::size_t no, const char* src, const char* field) {
  return Vec3(number(f[i0], no, i0 + 1, src, field), number(f[i0 + 1], no, i0 + 2, src, field),
              number(f[i0 + 2], no, i0 + 3, src, field));
}

void expectFields(const std::vector<std::string_view>& f, std::size_t n, std::string_view kind, std::size_t no,
                  const char* src) {
  if (f.empty() || f[0] != kind)
    throw InputError(SourceLocation{src, no, 1, "type"}, "expected a '" + std::string(kind) + "' line");
  if (f.size() != n)
    throw InputError(SourceLocation{src, no, 0, f.size() < n ? "missing field" : "extra field"},
                     fmt::format("a '{}' line has {} fields, this one {}", kind, n, f.size()));
}

}  // namespace

std::string swarmEventTopic(int agent) { return fmt::format("{}{:04d}", kSwarmEventTopicPrefix, agent); }

std::string formatTwrLine(double t_s, int peer, double range_m) { return fmt::format("twr,{},{},{}", t_s, peer, range_m); }

bool parseTwrLine(std::string_view line, std::size_t line_no, double* t_s, int* peer, double* range_m) {
  if (line.substr(0, 4) != "twr,") return false;
  const auto f = split(line);
  expectFields(f, 4, "twr", line_no, "<zmq>");
  *t_s = number(f[1], line_no, 2, "<zmq>", "t");
  *peer = static_cast<int>(integer(f[2], line_no, 3, "<zmq>", "peer"));
  *range_m = number(f[3], line_no, 4, "<zmq>", "range_m");
  return true;
}

std::string formatBelief(const NeighbourBelief& b, std::int64_t send_ns) {
  std::string out = fmt::format("belief,{},{},{},{},{},{}", b.agent, b.t_s, send_ns, b.tag.m.x(), b.tag.m.y(), b.tag.m.z());
  appendUpper(out, b.tag.V);
  fmt::format_to(std::back_inserter(out), ",{},{},{},{},{},{}", b.w_v.x(), b.w_v.y(), b.w_v.z(), b.cov_v(0, 0),
                 b.cov_v(1, 1), b.cov_v(2, 2));
  return out;
}

NeighbourBelief parseBelief(std::string_view line, std::size_t message_no, std::int64_t* send_ns) {
  const auto f = split(line);
  expectFields(f, 19, "belief", message_no, "<zmq>");
  NeighbourBelief b;
  b.agent = static_cast<int>(integer(f[1], message_no, 2, "<zmq>", "agent"));
  b.t_s = number(f[2], message_no, 3, "<zmq>", "t");
  const std::int64_t ns = integer(f[3], message_no, 4, "<zmq>", "send_ns");
  if (send_ns) *send_ns = ns;
  b.tag.m = read3(f, 4, message_no, "<zmq>", "m");
  b.tag.V = readUpper(f, 7, message_no, "<zmq>");
  b.w_v = read3(f, 13, message_no, "<zmq>", "v");
  b.cov_v = read3(f, 16, message_no, "<zmq>", "cov_v").asDiagonal();
  return b;
}

std::string formatSwarmEstimate(const SwarmEstimate& e) {
  std::string out = fmt::format("est,{},{},{},{},{}", e.agent, e.t_s, e.p_coop.x(), e.p_coop.y(), e.p_coop.z());
  appendUpper(out, e.cov_coop);
  fmt::format_to(std::back_inserter(out), ",{},{},{}", e.p_indep.x(), e.p_indep.y(), e.p_indep.z());
  appendUpper(out, e.cov_indep);
  return out;
}

SwarmEstimate parseSwarmEstimate(std::string_view line, std::size_t message_no) {
  const auto f = split(line);
  expectFields(f, 21, "est", message_no, "<zmq>");
  SwarmEstimate e;
  e.agent = static_cast<int>(integer(f[1], message_no, 2, "<zmq>", "agent"));
  e.t_s = number(f[2], message_no, 3, "<zmq>", "t");
  e.p_coop = read3(f, 3, message_no, "<zmq>", "p_coop");
  e.cov_coop = readUpper(f, 6, message_no, "<zmq>");
  e.p_indep = read3(f, 12, message_no, "<zmq>", "p_indep");
  e.cov_indep = readUpper(f, 15, message_no, "<zmq>");
  return e;
}

}  // namespace uwb
