/** @file cmd_swarm.cpp
 *  @brief `uwbtdoa swarm --agents N --scenario NAME [--duration S] [--seed K] [--speed 1|max] [--imu-rate HZ]
 *         [--fusion extrinsic|ci|naive] [--json] [--out DIR]`: cooperative localization of N simulated agents, each
 *         in its own process, over ZeroMQ on loopback (docs/io.md §7).
 *
 *  This process simulates the swarm and publishes each agent's sensor stream (one topic per agent), runs the
 *  belief bus (ZeroMQ's built-in XSUB/XPUB proxy) and the collector, and fork/execs N `uwbtdoa swarm-agent`
 *  processes (a hidden subcommand). Each agent runs a cooperative and an independent Estimator, publishes its belief
 *  on the bus and fuses its neighbours' beliefs with its TWR (message-passing.md G20–G22). Its estimates and its
 *  final report go to the parent on a reliable channel of their own (PUSH → PULL, never dropped), not over the lossy
 *  bus; a run fails, naming each failed agent and why, when an agent dies, sends no report or scores no sample.
 *  SIGINT/SIGTERM: every agent is sent SIGTERM and reaped, nothing is written, exit 130.
 */
#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "Command.h"
#include "StopSignal.h"
#include "uwb/core/Error.h"
#include "uwb/eval/Localization.h"
#include "uwb/io/FileAccess.h"
#include "uwb/stream/LatencyStats.h"
#include "uwb/stream/LineProtocol.h"
#include "uwb/stream/SwarmWire.h"
#include "uwb/stream/ZmqWire.h"

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

constexpr int kExitInterrupted = 130;
/// Sensor events of one agent are sent in batches of this much sensor time [s].
constexpr double kBatch_s = 0.01;
/// Agents publish an estimate pair for the collector this often (sensor time) [s].
constexpr double kEstimatePeriod_s = 0.1;

struct SwarmArgs {
  int agents = 3;
  std::string scenario = "nominal", speed = "1", fusion = "extrinsic", out;
  double duration = 20.0, imu_rate = 1000.0;
  std::uint64_t seed = 1;
  bool json_out = false, in_process = false;
};

struct AgentArgs {
  int id = 0, agents = 0;
  std::string scenario, fusion, events, bus_in, bus_out, report;
  double duration = 0.0;
};

uwb::CooperativeAgentOptions agentOptions(const std::string& fusion) {
  uwb::CooperativeAgentOptions o;
  if (fusion == "extrinsic") {
    o.broadcast = uwb::BeliefSource::kIndependent;
    o.range.fusion = uwb::NeighbourFusion::kNaive;  // exact: the belief holds nothing of the receiver's (G21)
  } else if (fusion == "ci") {
    o.broadcast = uwb::BeliefSource::kCooperative;
    o.range.fusion = uwb::NeighbourFusion::kCovarianceIntersection;
  } else if (fusion == "naive") {
    o.broadcast = uwb::BeliefSource::kCooperative;
    o.range.fusion = uwb::NeighbourFusion::kNaive;
  } else {
    throw uwb::InputError("--fusion: expected extrinsic, ci or naive, got '" + fusion + "'");
  }
  return o;
}

bool recvPair(zmq::socket_t& s, std::string& topic, std::string& body, int timeout_ms) {
  zmq::pollitem_t item{s.handle(), 0, ZMQ_POLLIN, 0};
  try {
    if (zmq::poll(&item, 1, std::chrono::milliseconds(timeout_ms)) == 0) return false;
  } catch (const zmq::error_t& e) {
    if (e.num() == EINTR) return false;
    throw;
  }
  zmq::message_t t, b;
  if (!s.recv(t, zmq::recv_flags::dontwait)) return false;
  if (!t.more()) throw uwb::InputError(uwb::SourceLocation{"<zmq>", 0, 0, "topic"}, "a message must have two frames");
  (void)s.recv(b);
  topic = t.to_string();
  body = b.to_string();
  return true;
}

void sendPair(zmq::socket_t& s, std::string_view topic, std::string_view body, bool block) {
  const zmq::send_flags f = block ? zmq::send_flags::none : zmq::send_flags::dontwait;
  if (!s.send(zmq::buffer(topic), f | zmq::send_flags::sndmore)) throw std::runtime_error("dropped");
  s.send(zmq::buffer(body), zmq::send_flags::none);
}

// ---------------------------------------------------------------- agent process
/// One agent process: its estimators, its four sockets and what it counts for its final report.
class AgentProcess {
 public:
  explicit AgentProcess(const AgentArgs& a)
      : a_(a),
        sc_(uwb::sim::makeSwarmScenario(a.scenario, a.agents, a.duration)),
        params_(uwb::EkfParams::defaults()),
        agent_(a.id, params_, uwb::anchorTableFromSurvey(sc_.survey, params_.anchor_sigma_m), agentOptions(a.fusion)) {
    ev_.set(zmq::sockopt::rcvhwm, 0);
    ev_.set(zmq::sockopt::linger, 0);
    ev_.set(zmq::sockopt::subscribe, uwb::swarmEventTopic(a.id));
    ev_.connect(a.events);
    bus_sub_.set(zmq::sockopt::linger, 0);
    bus_sub_.set(zmq::sockopt::subscribe, std::string(uwb::kSwarmBeliefTopic));
    bus_sub_.connect(a.bus_out);
    bus_pub_.set(zmq::sockopt::linger, 2000);
    bus_pub_.connect(a.bus_in);
    // estimates and the final report: a PUSH that blocks at the high-water mark and, at close, waits up to 60 s until
    // all is delivered (the parent's PULL drains it; a stopped agent waits for nothing)
    report_.set(zmq::sockopt::linger, 60000);
    report_.connect(a.report);
  }

  /// Handles beliefs and event batches until the end of the events or a stop signal; then sends the report.
  void run() {
    zmq::pollitem_t items[2] = {{ev_.handle(), 0, ZMQ_POLLIN, 0}, {bus_sub_.handle(), 0, ZMQ_POLLIN, 0}};
    std::string topic, body;
    while (*uwb::app::stopFlag() == 0) {
      try {
        zmq::poll(items, 2, std::chrono::milliseconds(100));
      } catch (const zmq::error_t& e) {
        if (e.num() == EINTR) continue;
        throw;
      }
      receiveBeliefs();  // the newest neighbours' beliefs before the next batch of measurements
      if (!recvPair(ev_, topic, body, 0)) continue;
      if (body == uwb::kEndOfEvents) break;
      handleBatch(body);
    }
    if (*uwb::app::stopFlag() != 0) {
      report_.set(zmq::sockopt::linger, 0);  // interrupted (or the parent died): no report, nothing to wait for
      return;
    }
    sendPair(report_, uwb::kSwarmDoneTopic, reportJson().dump(), true);
  }

 private:
  void receiveBeliefs() {
    std::string topic, body;
    while (recvPair(bus_sub_, topic, body, 0)) {
      std::int64_t send_ns = 0;
      const uwb::NeighbourBelief b = uwb::parseBelief(body, ++msg_no_, &send_ns);
      if (b.agent == a_.id) continue;
      lat_belief_.add(static_cast<double>(nowNs() - send_ns) * 1e-9);
      agent_.addBelief(b);
      ++n_beliefs_in_;
    }
  }

  /// One batch of event lines; its first line "# SEND_NS" is the parent's send time.
  void handleBatch(const std::string& body) {
    std::size_t pos = 0, line_no = 0;
    std::int64_t send_ns = 0;
    while (pos < body.size()) {
      const std::size_t nl = body.find('\n', pos);
      const std::string_view line(body.data() + pos, (nl == std::string::npos ? body.size() : nl) - pos);
      pos = nl == std::string::npos ? body.size() : nl + 1;
      ++line_no;
      if (line_no == 1 && line.size() > 2 && line[0] == '#') {
        send_ns = std::stoll(std::string(line.substr(2)));
        continue;
      }
      if (!handleLine(line, line_no)) continue;
      ++n_events_;
      if (agent_.beliefDue() && publish(uwb::kSwarmBeliefTopic, uwb::formatBelief(agent_.belief(), nowNs())))
        ++n_beliefs_sent_;
      sendEstimateIfDue();
    }
    lat_event_.add(static_cast<double>(nowNs() - send_ns) * 1e-9);  // batch sent → last event of it handled
  }

  /// A TWR, IMU or TDoA line to the agent; false for any other event.
  bool handleLine(std::string_view line, std::size_t line_no) {
    double t = 0.0, range = 0.0;
    int peer = -1;
    if (uwb::parseTwrLine(line, line_no, &t, &peer, &range)) {
      agent_.addRange(t, peer, range);
      ++n_twr_;
      return true;
    }
    const uwb::StreamEvent e = uwb::parseEventLine(line, line_no, "<zmq>");
    if (e.kind == uwb::StreamEvent::Kind::kImu) agent_.addImu(e.t_s, e.imu);
    else if (e.kind == uwb::StreamEvent::Kind::kTdoa) agent_.addTdoa(e.tdoa);
    else return false;
    return true;
  }

  bool publish(std::string_view topic, const std::string& body) {
    try {
      sendPair(bus_pub_, topic, body, false);
      return true;
    } catch (const std::runtime_error&) {
      ++n_dropped_;
      return false;
    }
  }

  /// The cooperative and the independent estimate to the parent, every kEstimatePeriod_s of sensor time.
  void sendEstimateIfDue() {
    const double t_now = agent_.cooperative().time();
    if (!(t_now >= t_next_est_ && agent_.cooperative().ready() && agent_.independent().ready())) return;
    t_next_est_ = t_now + kEstimatePeriod_s;
    const uwb::LocalizerEstimate c = agent_.cooperative().estimate(), i = agent_.independent().estimate();
    uwb::SwarmEstimate se{a_.id, t_now, c.x.w_p_b, i.x.w_p_b, c.cov_pose.topLeftCorner<3, 3>(),
                          i.cov_pose.topLeftCorner<3, 3>()};
    sendPair(report_, uwb::kSwarmEstimateTopic, uwb::formatSwarmEstimate(se), true);
    ++n_est_;
  }

  json reportJson() const {
    const uwb::LocalizerSummary& s = agent_.cooperative().summary();
    return {{"agent", a_.id},
            {"events", n_events_},
            {"twr", n_twr_},
            {"twr_used", s.n_coop_used},
            {"twr_rejected", s.n_coop_rejected},
            {"twr_without_belief", agent_.rangesWithoutBelief()},
            {"mean_omega", s.n_coop_used ? s.coop_omega_sum / static_cast<double>(s.n_coop_used) : 1.0},
            {"beliefs_sent", n_beliefs_sent_},
            {"beliefs_received", n_beliefs_in_},
            {"estimates_sent", n_est_},
            {"bus_dropped", n_dropped_},
            {"event_latency_p50_s", lat_event_.quantile(0.5)},
            {"event_latency_p99_s", lat_event_.quantile(0.99)},
            {"belief_latency_p50_s", lat_belief_.quantile(0.5)},
            {"belief_latency_p99_s", lat_belief_.quantile(0.99)}};
  }

  const AgentArgs& a_;
  const uwb::sim::SwarmScenario sc_;
  const uwb::EkfParams params_;
  uwb::CooperativeAgent agent_;
  zmq::context_t ctx_;
  zmq::socket_t ev_{ctx_, zmq::socket_type::sub}, bus_sub_{ctx_, zmq::socket_type::sub},
      bus_pub_{ctx_, zmq::socket_type::pub}, report_{ctx_, zmq::socket_type::push};
  uwb::LatencyStats lat_event_, lat_belief_;
  std::size_t n_events_ = 0, n_beliefs_in_ = 0, n_beliefs_sent_ = 0, n_dropped_ = 0, n_est_ = 0, n_twr_ = 0;
  std::size_t msg_no_ = 0;
  double t_next_est_ = 0.0;
};

void runAgent(const AgentArgs& a) {
  uwb::app::installStopHandlers();
  AgentProcess(a).run();
}

// ---------------------------------------------------------------- parent: simulator, bus, collector
struct Children {
  std::vector<pid_t> pids;
  std::vector<int> status;  ///< waitpid status of each agent once it exited; -1 while running
  void terminateAll() {
    for (pid_t p : pids)
      if (p > 0) ::kill(p, SIGTERM);
    reapAll(3000);
    for (pid_t p : pids)
      if (p > 0) ::kill(p, SIGKILL);
    reapAll(1000);
  }
  /// Reaps exited children; returns how many are still running.
  std::size_t reap() {
    std::size_t running = 0;
    status.resize(pids.size(), -1);
    for (std::size_t i = 0; i < pids.size(); ++i) {
      pid_t& p = pids[i];
      if (p <= 0) continue;
      int st = 0;
      const pid_t r = ::waitpid(p, &st, WNOHANG);
      if (r == p) {
        if (!(WIFEXITED(st) && WEXITSTATUS(st) == 0)) ++failed;
        status[i] = st;
        p = 0;
      } else {
        ++running;
      }
    }
    return running;
  }
  void reapAll(int timeout_ms) {
    const auto end = Clock::now() + std::chrono::milliseconds(timeout_ms);
    while (reap() > 0 && Clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::size_t failed = 0;
};

/// Why agent k's run has no result (empty: it has one).
std::string agentFailure(const std::vector<int>& status, std::size_t k, bool reported, std::size_t samples) {
  const int st = k < status.size() ? status[k] : -1;
  if (st != -1 && WIFSIGNALED(st))
    return fmt::format("killed by signal {} ({}){}", WTERMSIG(st), ::strsignal(WTERMSIG(st)),
                       WTERMSIG(st) == SIGKILL ? "; out of memory?" : "");
  if (st != -1 && WIFEXITED(st) && WEXITSTATUS(st) != 0)
    return fmt::format("exited with code {} (its error is printed above)", WEXITSTATUS(st));
  if (!reported) return st == -1 ? "still running without a report at the end" : "exited without sending its report";
  if (samples == 0) return "no estimate in its scoring window (0 samples: no RMSE)";
  return {};
}

std::string selfExe() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

void validateSwarmArgs(const SwarmArgs& a) {
  if (a.speed != "1" && a.speed != "max") throw uwb::InputError("--speed: expected 1 or max, got '" + a.speed + "'");
  agentOptions(a.fusion);  // validates --fusion
  if (!(a.imu_rate >= 50.0 && a.imu_rate <= 1000.0)) throw uwb::InputError("--imu-rate: expected 50 … 1000 Hz");
  if (!a.out.empty()) uwb::checkOutputDirectory(a.out, "--out");
}

json scoreRowJson(const uwb::SwarmScore::Row& r) {
  return {{"samples", r.n}, {"rmse_coop_m", r.rmse_coop_m}, {"rmse_indep_m", r.rmse_indep_m},
          {"nees_coop", r.nees_coop}, {"nees_indep", r.nees_indep}};
}

/// --in-process: the same agents in this process, events merged in sensor time, beliefs delivered after 10 ms (no
/// ZeroMQ); prints the overall scores.
void runSwarmInProcess(const SwarmArgs& a, const uwb::sim::SwarmScenario& sc, const uwb::sim::SwarmSimResult& sim) {
  uwb::SwarmRunOptions o;
  o.agent = agentOptions(a.fusion);
  o.belief_latency_s = 0.01;
  const uwb::SwarmScore sc_in = uwb::runSwarmInProcess(sc, sim, o);
  const uwb::SwarmScore::Row r = sc_in.overall();
  if (r.n == 0)
    throw std::runtime_error("swarm: no estimate of any agent fell in its scoring window (0 samples: no RMSE); "
                             "a longer --duration?");
  json j = {{"scenario", a.scenario}, {"agents", a.agents}, {"fusion", a.fusion}, {"in_process", true},
            {"overall", scoreRowJson(r)}};
  std::cout << (a.json_out ? j.dump() : j.dump(2)) << "\n";
}

/// The ipc endpoints of one run, in a private directory under the system's temporary directory ($TMPDIR, else /tmp).
struct Endpoints {
  std::string dir, events, bus_in, bus_out, report;
};

Endpoints makeEndpoints() {
  std::error_code tmp_ec;
  const std::filesystem::path tmp_root = std::filesystem::temp_directory_path(tmp_ec);
  std::string dir_tmpl = ((tmp_ec ? std::filesystem::path("/tmp") : tmp_root) / "uwbtdoa-swarm-XXXXXX").string();
  if (::mkdtemp(dir_tmpl.data()) == nullptr)
    throw uwb::FileError(fmt::format("swarm: cannot create a directory for the ipc endpoints in {}",
                                     std::filesystem::path(dir_tmpl).parent_path().string()));
  const std::string dir = dir_tmpl;
  return {dir, "ipc://" + dir + "/events", "ipc://" + dir + "/bus-in", "ipc://" + dir + "/bus-out",
          "ipc://" + dir + "/report"};
}

/// What the publisher sent and how far it fell behind the wall clock.
struct PublishStats {
  std::size_t n_msgs = 0, n_lines = 0;
  uwb::LatencyStats lateness;
  Clock::time_point t_wall0;
  double publish_wall_s = 0.0;
};

/// Per agent, the indices of the TWR observations it takes part in.
std::vector<std::vector<std::size_t>> twrByAgent(const uwb::sim::SwarmSimResult& sim, int agents) {
  std::vector<std::vector<std::size_t>> twr_of(static_cast<std::size_t>(agents));
  for (std::size_t i = 0; i < sim.twr.size(); ++i) {
    twr_of[static_cast<std::size_t>(sim.twr[i].agent_i)].push_back(i);
    twr_of[static_cast<std::size_t>(sim.twr[i].agent_j)].push_back(i);
  }
  return twr_of;
}

/// Where agent k's streams have been sent up to.
struct Cursor {
  std::size_t imu = 0, tdoa = 0, twr = 0;
};

/// Appends agent k's events before t_end to body, merged in time order: IMU before TDoA before TWR at equal stamps.
/// Returns how many lines it appended.
std::size_t appendBatch(const uwb::SensorLog& log, const std::vector<std::size_t>& tw,
                        const uwb::sim::SwarmSimResult& sim, int k, double t_end, Cursor& c, std::string& body) {
  std::size_t n = 0;
  while (true) {
    const double ti = c.imu < log.imu.size() ? log.imu[c.imu].t_s : 1e300;
    const double td = c.tdoa < log.tdoa.size() ? log.tdoa[c.tdoa].t_s : 1e300;
    const double tr = c.twr < tw.size() ? sim.twr[tw[c.twr]].t_s : 1e300;
    const double t = std::min({ti, td, tr});
    if (!(t < t_end)) break;
    if (ti == t) {
      body += uwb::formatImuLine(ti, log.imu[c.imu++].imu);
    } else if (td == t) {
      body += uwb::formatTdoaLine(log.tdoa[c.tdoa++]);
    } else {
      const uwb::sim::TwrObservation& r = sim.twr[tw[c.twr++]];
      body += uwb::formatTwrLine(r.t_s, r.agent_i == k ? r.agent_j : r.agent_i, r.range_m);
    }
    body += '\n';
    ++n;
  }
  return n;
}

/// The parent's side of a run: the sensor-event publisher, the belief bus (XSUB/XPUB proxy), the collector of
/// estimates and reports (a thread of its own) and the agent processes.
class SwarmParent {
 public:
  SwarmParent(const SwarmArgs& a, const uwb::sim::SwarmScenario& sc, Endpoints eps)
      : a_(a), sc_(sc), eps_(std::move(eps)), score_(a.agents), done_(static_cast<std::size_t>(a.agents)) {
    openSockets();
    proxy_ = std::thread([this] {
      try {
        zmq::proxy(xsub_, xpub_);
      } catch (const zmq::error_t&) {
        // context shut down: the bus is closed
      }
    });
    collect_ = std::thread([this] { collect(); });
  }

  /// fork/execs one `uwbtdoa swarm-agent` per agent.
  void spawnAgents() {
    const std::string exe = selfExe();
    for (int k = 0; k < a_.agents; ++k) {
      const std::vector<std::string> argv_s = {exe, "swarm-agent", "--id", std::to_string(k), "--agents",
                                               std::to_string(a_.agents), "--scenario", a_.scenario, "--duration",
                                               fmt::format("{}", a_.duration), "--fusion", a_.fusion, "--events",
                                               eps_.events, "--bus-in", eps_.bus_in, "--bus-out", eps_.bus_out,
                                               "--report", eps_.report};
      const pid_t pid = ::fork();
      if (pid < 0) {
        children_.terminateAll();
        shutdown();
        throw std::runtime_error("swarm: fork failed");
      }
      if (pid == 0) {
        ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // an agent never outlives the swarm
        std::vector<char*> argv;
        for (const std::string& s : argv_s) argv.push_back(const_cast<char*>(s.c_str()));
        argv.push_back(nullptr);
        ::execv(exe.c_str(), argv.data());
        ::_exit(127);
      }
      children_.pids.push_back(pid);
    }
  }

  /// Waits until every agent subscribed to its event topic (XPUB sees the subscriptions).
  void waitForSubscriptions() {
    std::set<std::string> subscribed;
    // 100 processes starting on a busy machine: 30 s, and 0.5 s more per agent
    const auto wait_s = std::chrono::milliseconds(30000 + 500 * a_.agents);
    const auto deadline = Clock::now() + wait_s;
    while (static_cast<int>(subscribed.size()) < a_.agents) {
      if (interrupted()) abort("");
      if (Clock::now() > deadline)
        abort(fmt::format("{} of {} agents did not subscribe within {} s",
                          a_.agents - static_cast<int>(subscribed.size()), a_.agents,
                          std::chrono::duration_cast<std::chrono::seconds>(wait_s).count()));
      if (children_.reap() < static_cast<std::size_t>(a_.agents))
        abort("an agent exited at start-up: " + exitedAgents());
      zmq::pollitem_t item{events_.handle(), 0, ZMQ_POLLIN, 0};
      try {
        if (zmq::poll(&item, 1, std::chrono::milliseconds(50)) == 0) continue;
      } catch (const zmq::error_t& e) {
        if (e.num() == EINTR) continue;
        throw;
      }
      zmq::message_t m;
      if (events_.recv(m, zmq::recv_flags::dontwait) && m.size() > 1 && m.data<char>()[0] == 1)
        subscribed.insert(std::string(m.data<char>() + 1, m.size() - 1));
    }
  }

  /// Publishes per agent batches of kBatch_s of sensor time, paced to the wall clock when realtime (--speed 1), then
  /// the end of the events.
  PublishStats publish(const uwb::sim::SwarmSimResult& sim, bool realtime) {
    std::vector<uwb::SensorLog> logs;
    for (const auto& ag : sim.agents) logs.push_back(uwb::sensorLogFromFlight(ag.flight));
    const std::vector<std::vector<std::size_t>> twr_of = twrByAgent(sim, a_.agents);
    std::vector<Cursor> cur(static_cast<std::size_t>(a_.agents));
    PublishStats st;
    st.t_wall0 = Clock::now();
    std::string body;
    for (double t_end = kBatch_s; t_end < a_.duration + kBatch_s; t_end += kBatch_s) {
      if (interrupted()) abort("");
      if (realtime) {
        const auto due = st.t_wall0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(t_end));
        std::this_thread::sleep_until(due);
        st.lateness.add(std::chrono::duration<double>(Clock::now() - due).count());
      }
      if (children_.reap() < static_cast<std::size_t>(a_.agents)) abort("an agent exited early: " + exitedAgents());
      for (int k = 0; k < a_.agents; ++k) {
        const std::size_t kk = static_cast<std::size_t>(k);
        body = fmt::format("# {}\n", nowNs());
        const std::size_t n = appendBatch(logs[kk], twr_of[kk], sim, k, t_end, cur[kk], body);
        st.n_lines += n;
        if (n == 0) continue;
        body.pop_back();
        sendPair(events_, uwb::swarmEventTopic(k), body, true);
        ++st.n_msgs;
      }
    }
    for (int k = 0; k < a_.agents; ++k) sendPair(events_, uwb::swarmEventTopic(k), uwb::kEndOfEvents, true);
    st.publish_wall_s = std::chrono::duration<double>(Clock::now() - st.t_wall0).count();
    return st;
  }

  /// Waits for every agent's report; true when it ended because nothing arrived for a minute (stalled).
  bool waitForReports() {
    // agents far behind the publisher (many agents at --speed max on a busy machine) still make progress (estimates
    // arrive), so the wait ends only after 60 s without any
    constexpr auto kNoProgress = std::chrono::seconds(60);
    constexpr auto kLastReports = std::chrono::seconds(5);  // after every agent exited: reports still in the pipe
    Clock::time_point all_exited{};
    {
      std::lock_guard<std::mutex> lock(mu_);
      t_progress_ = std::max(t_progress_, Clock::now());
    }
    while (true) {
      if (interrupted()) abort("");
      Clock::time_point last_progress;
      {
        std::lock_guard<std::mutex> lock(mu_);
        if (n_done_ == static_cast<std::size_t>(a_.agents) || !collector_error_.empty()) return false;
        last_progress = t_progress_;
      }
      if (Clock::now() - last_progress > kNoProgress) return true;  // the agents still running are reported below
      if (children_.reap() == 0) {
        if (all_exited == Clock::time_point{}) all_exited = Clock::now();
        else if (Clock::now() - all_exited > kLastReports) return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  /// Stops the agents (those still running when stalled), the collector and the bus; then every agent has a result,
  /// or the run fails naming each one that has none and why.
  void finish(bool stalled) {
    children_.reap();
    const std::vector<int> status_at_end = children_.status;  // -1: still running (then stopped below)
    if (stalled) children_.terminateAll();
    children_.reapAll(10000);
    shutdown();
    if (!collector_error_.empty()) throw uwb::InputError("swarm collector: " + collector_error_);
    std::vector<std::string> why;
    for (int k = 0; k < a_.agents; ++k) {
      const std::size_t kk = static_cast<std::size_t>(k);
      const std::string w = agentFailure(status_at_end, kk, !done_[kk].is_null(), score_.agent(k).n);
      if (!w.empty()) why.push_back(fmt::format("agent {}: {}", k, w));
    }
    if (!why.empty()) {
      std::string text = fmt::format("swarm: {} of {} agent(s) failed{}", why.size(), a_.agents,
                                     stalled ? " (no estimate or report for 60 s)" : "");
      for (std::size_t i = 0; i < why.size() && i < 20; ++i) text += "\n  " + why[i];
      if (why.size() > 20) text += fmt::format("\n  … and {} more", why.size() - 20);
      throw std::runtime_error(text);
    }
  }

  const uwb::SwarmScore& score() const { return score_; }
  const std::vector<json>& reports() const { return done_; }
  std::size_t estimatesReceived() const { return n_est_; }

 private:
  void openSockets() {
    events_.set(zmq::sockopt::xpub_nodrop, 1);  // sensor events are never dropped: the publisher waits
    events_.set(zmq::sockopt::sndhwm, 100000);
    events_.set(zmq::sockopt::linger, 0);
    events_.bind(eps_.events);
    xsub_.set(zmq::sockopt::linger, 0);
    xpub_.set(zmq::sockopt::linger, 0);
    xsub_.bind(eps_.bus_in);
    xpub_.bind(eps_.bus_out);
    // collector: subscribed before any agent runs
    collector_.set(zmq::sockopt::rcvhwm, 0);
    collector_.set(zmq::sockopt::linger, 0);
    collector_.set(zmq::sockopt::subscribe, std::string(uwb::kSwarmBeliefTopic));
    collector_.connect(eps_.bus_out);
    // estimates and reports: a reliable channel of their own (PULL, no high-water mark), not the lossy bus
    reports_.set(zmq::sockopt::rcvhwm, 0);
    reports_.set(zmq::sockopt::linger, 0);
    reports_.bind(eps_.report);
  }

  /// The collector thread: scores the estimates against the truth, keeps the first report of each agent.
  void collect() {
    std::string topic, body;
    std::size_t no = 0;
    std::vector<uwb::sim::Trajectory> truth;
    for (const auto& ag : sc_.agents) truth.emplace_back(ag.trajectory);
    try {
      while (collecting_.load()) {
        zmq::pollitem_t items[2] = {{reports_.handle(), 0, ZMQ_POLLIN, 0}, {collector_.handle(), 0, ZMQ_POLLIN, 0}};
        try {
          zmq::poll(items, 2, std::chrono::milliseconds(50));
        } catch (const zmq::error_t& e) {
          if (e.num() == EINTR) continue;
          throw;
        }
        if (!recvPair(reports_, topic, body, 0) && !recvPair(collector_, topic, body, 0)) continue;
        ++no;
        std::lock_guard<std::mutex> lock(mu_);
        if (topic != uwb::kSwarmBeliefTopic) t_progress_ = Clock::now();
        if (topic == uwb::kSwarmEstimateTopic) {
          const uwb::SwarmEstimate e = uwb::parseSwarmEstimate(body, no);
          ++n_est_;
          if (e.agent >= 0 && e.agent < a_.agents && uwb::swarmScoringWindow(sc_, e.agent, e.t_s))
            score_.add(e.agent, truth[static_cast<std::size_t>(e.agent)].evaluate(e.t_s).w_p, e.p_coop, e.cov_coop,
                       e.p_indep, e.cov_indep);
        } else if (topic == uwb::kSwarmDoneTopic) {
          const json d = json::parse(body);
          const int k = d.at("agent").get<int>();
          if (k >= 0 && k < a_.agents && done_[static_cast<std::size_t>(k)].is_null()) {
            done_[static_cast<std::size_t>(k)] = d;
            ++n_done_;
          }
        } else if (topic == uwb::kSwarmBeliefTopic) {
          ++n_beliefs_;
        }
      }
    } catch (const std::exception& ex) {
      std::lock_guard<std::mutex> lock(mu_);
      collector_error_ = ex.what();
    }
  }

  void shutdown() {
    collecting_ = false;
    collect_.join();
    ctx_.shutdown();
    proxy_.join();
    std::error_code ec;
    std::filesystem::remove_all(eps_.dir, ec);
  }

  bool interrupted() const { return *uwb::app::stopFlag() != 0; }

  std::string exitedAgents() const {
    std::string text;
    for (std::size_t k = 0; k < children_.status.size(); ++k)
      if (children_.status[k] != -1)
        text += fmt::format("{}agent {} {}", text.empty() ? "" : "; ", k, agentFailure(children_.status, k, false, 0));
    return text;
  }

  /// Stops every agent, the collector and the bus; on a signal (empty why) exits 130, else throws.
  void abort(const std::string& why) {
    children_.terminateAll();
    shutdown();
    if (why.empty()) {
      std::cerr << "swarm: interrupted; all agents stopped, nothing written\n";
      std::exit(kExitInterrupted);
    }
    throw std::runtime_error("swarm: " + why);
  }

  const SwarmArgs& a_;
  const uwb::sim::SwarmScenario& sc_;
  const Endpoints eps_;
  zmq::context_t ctx_;
  zmq::socket_t events_{ctx_, zmq::socket_type::xpub}, xsub_{ctx_, zmq::socket_type::xsub},
      xpub_{ctx_, zmq::socket_type::xpub}, collector_{ctx_, zmq::socket_type::sub},
      reports_{ctx_, zmq::socket_type::pull};
  std::thread proxy_;
  Children children_;
  std::atomic<bool> collecting_{true};
  std::mutex mu_;
  uwb::SwarmScore score_;
  std::vector<json> done_;
  std::size_t n_done_ = 0, n_est_ = 0, n_beliefs_ = 0;
  Clock::time_point t_progress_ = Clock::now();  ///< the last estimate or report received
  std::string collector_error_;
  std::thread collect_;
};

/// The agents' reports summed up: latency quantiles over agents, totals, and per agent its report and scores.
struct AgentTotals {
  uwb::LatencyStats ev50, ev99, bl50, bl99;
  std::size_t bus_dropped = 0, beliefs_sent = 0, twr_used = 0, twr_total = 0;
  json per_agent = json::array();
};

AgentTotals agentTotals(int agents, const std::vector<json>& done, const uwb::SwarmScore& score) {
  AgentTotals t;
  for (int k = 0; k < agents; ++k) {
    const json& d = done[static_cast<std::size_t>(k)];
    t.ev50.add(d.value("event_latency_p50_s", 0.0));
    t.ev99.add(d.value("event_latency_p99_s", 0.0));
    if (!d.at("belief_latency_p50_s").is_null()) {
      t.bl50.add(d.value("belief_latency_p50_s", 0.0));
      t.bl99.add(d.value("belief_latency_p99_s", 0.0));
    }
    t.bus_dropped += d.at("bus_dropped").get<std::size_t>();
    t.beliefs_sent += d.at("beliefs_sent").get<std::size_t>();
    t.twr_used += d.at("twr_used").get<std::size_t>();
    t.twr_total += d.at("twr").get<std::size_t>();
    json aj = d;
    aj.update(scoreRowJson(score.agent(k)));
    t.per_agent.push_back(aj);
  }
  return t;
}

/// Wall-clock times of a run's phases [s].
struct SwarmWallTimes {
  double simulate_s = 0.0, publish_s = 0.0, total_s = 0.0;
};

json swarmReportJson(const SwarmArgs& a, const AgentTotals& t, const uwb::SwarmScore::Row& all,
                     const PublishStats& pub, std::size_t n_est, const SwarmWallTimes& wall) {
  const double publish_wall_s = wall.publish_s;
  const double dur = a.duration;
  return {{"scenario", a.scenario},
          {"agents", a.agents},
          {"duration_s", dur},
          {"seed", a.seed},
          {"speed", a.speed},
          {"imu_rate_hz", a.imu_rate},
          {"fusion", a.fusion},
          {"overall", scoreRowJson(all)},
          {"rates",
           {{"event_messages_per_s", static_cast<double>(pub.n_msgs) / publish_wall_s},
            {"event_lines_per_s", static_cast<double>(pub.n_lines) / publish_wall_s},
            {"beliefs_per_s", static_cast<double>(t.beliefs_sent) / publish_wall_s},
            {"estimates_per_s", static_cast<double>(n_est) / publish_wall_s},
            {"twr_per_s", static_cast<double>(t.twr_total) / publish_wall_s},
            {"twr_used", t.twr_used},
            {"bus_dropped", t.bus_dropped},
            {"sensor_events_dropped", 0}}},
          {"latency_s",
           {{"event_p50_median_over_agents", t.ev50.quantile(0.5)},
            {"event_p99_max_over_agents", t.ev99.quantile(1.0)},
            {"belief_p50_median_over_agents", t.bl50.quantile(0.5)},
            {"belief_p99_max_over_agents", t.bl99.quantile(1.0)},
            {"publisher_lateness_p99", pub.lateness.quantile(0.99)},
            {"publisher_lateness_max", pub.lateness.quantile(1.0)}}},
          {"wall_s", {{"simulate", wall.simulate_s}, {"publish", publish_wall_s}, {"total", wall.total_s}}},
          {"per_agent", t.per_agent}};
}

/// --out: swarm_agents.csv (the scores per agent) and swarm_report.json, each written atomically.
void writeSwarmOutputs(const SwarmArgs& a, const uwb::SwarmScore& score, const json& rep) {
  std::string csv = "agent,samples,rmse_coop_m,rmse_indep_m,nees_coop,nees_indep\n";
  for (int k = 0; k < a.agents; ++k) {
    const uwb::SwarmScore::Row r = score.agent(k);
    csv += fmt::format("{},{},{},{},{},{}\n", k, r.n, r.rmse_coop_m, r.rmse_indep_m, r.nees_coop, r.nees_indep);
  }
  uwb::writeFileAtomically((std::filesystem::path(a.out) / "swarm_agents.csv").string(), csv, "swarm --out");
  uwb::writeFileAtomically((std::filesystem::path(a.out) / "swarm_report.json").string(), rep.dump(2) + "\n",
                           "swarm --out");
}

void printSwarmReport(const SwarmArgs& a, const SwarmParent& run, const AgentTotals& t, const PublishStats& pub,
                      const SwarmWallTimes& wall) {
  const bool realtime = a.speed == "1";
  const uwb::SwarmScore::Row all = run.score().overall();
  const double publish_wall_s = wall.publish_s;
  std::cout << fmt::format("swarm: {} agents, scenario {}, {} s, seed {}, speed {}, IMU {} Hz, fusion {}\n", a.agents,
                           a.scenario, a.duration, a.seed, a.speed, a.imu_rate, a.fusion);
  std::cout << "agent  samples  RMSE coop [m]  RMSE indep [m]  NEES coop  NEES indep  TWR used  beliefs in\n";
  for (int k = 0; k < a.agents; ++k) {
    const uwb::SwarmScore::Row r = run.score().agent(k);
    const json& d = run.reports()[static_cast<std::size_t>(k)];
    std::cout << fmt::format("{:5d}  {:7d}  {:13.3f}  {:14.3f}  {:9.2f}  {:10.2f}  {:8d}  {:10d}\n", k, r.n,
                             r.rmse_coop_m, r.rmse_indep_m, r.nees_coop, r.nees_indep,
                             d.at("twr_used").get<std::size_t>(), d.at("beliefs_received").get<std::size_t>());
  }
  std::cout << fmt::format("overall  {:5d}  {:13.3f}  {:14.3f}  {:9.2f}  {:10.2f}\n", all.n, all.rmse_coop_m,
                           all.rmse_indep_m, all.nees_coop, all.nees_indep);
  std::cout << fmt::format(
      "rates: {:.0f} event messages/s ({:.0f} lines/s), {:.0f} beliefs/s, {:.0f} estimates/s, {:.0f} TWR/s; "
      "dropped: 0 sensor events, {} bus messages\n",
      static_cast<double>(pub.n_msgs) / publish_wall_s, static_cast<double>(pub.n_lines) / publish_wall_s,
      static_cast<double>(t.beliefs_sent) / publish_wall_s,
      static_cast<double>(run.estimatesReceived()) / publish_wall_s, static_cast<double>(t.twr_total) / publish_wall_s,
      t.bus_dropped);
  std::cout << fmt::format(
      "latency: event batch sent → handled p50 {:.3f} ms (median over agents), p99 {:.3f} ms (worst agent); "
      "belief sent → received p50 {:.3f} ms, p99 {:.3f} ms{}\n",
      t.ev50.quantile(0.5) * 1e3, t.ev99.quantile(1.0) * 1e3, t.bl50.quantile(0.5) * 1e3, t.bl99.quantile(1.0) * 1e3,
      realtime ? fmt::format("; publisher behind schedule p99 {:.3f} ms, max {:.3f} ms",
                             pub.lateness.quantile(0.99) * 1e3, pub.lateness.quantile(1.0) * 1e3)
               : std::string());
  std::cout << fmt::format("wall: simulate {:.2f} s, publish {:.2f} s for {:.1f} s of flight, total {:.2f} s\n",
                           wall.simulate_s, publish_wall_s, a.duration, wall.total_s);
}

void runSwarm(const SwarmArgs& a) {
  validateSwarmArgs(a);
  uwb::app::installStopHandlers();
  const bool realtime = a.speed == "1";
  const uwb::sim::SwarmScenario sc = uwb::sim::makeSwarmScenario(a.scenario, a.agents, a.duration);
  uwb::sim::SimParams sp;
  sp.imu.rate_hz = a.imu_rate;
  const auto t_sim0 = Clock::now();
  const uwb::sim::SwarmSimResult sim = uwb::sim::simulateSwarm(sc, sp, a.seed);
  SwarmWallTimes wall;
  wall.simulate_s = std::chrono::duration<double>(Clock::now() - t_sim0).count();
  if (a.in_process) {
    runSwarmInProcess(a, sc, sim);
    return;
  }
  SwarmParent run(a, sc, makeEndpoints());
  run.spawnAgents();
  run.waitForSubscriptions();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the agents' bus connections settle
  const PublishStats pub = run.publish(sim, realtime);
  wall.publish_s = pub.publish_wall_s;
  const bool stalled = run.waitForReports();
  wall.total_s = std::chrono::duration<double>(Clock::now() - pub.t_wall0).count();
  run.finish(stalled);

  const AgentTotals totals = agentTotals(a.agents, run.reports(), run.score());
  const json rep = swarmReportJson(a, totals, run.score().overall(), pub, run.estimatesReceived(), wall);
  if (!a.out.empty()) writeSwarmOutputs(a, run.score(), rep);
  if (a.json_out) {
    std::cout << rep.dump() << "\n";
    return;
  }
  printSwarmReport(a, run, totals, pub, wall);
}

const bool kRegistered = uwb::app::registerCommand(
    {"swarm", "Cooperative localization of N simulated agents, one process each, over ZeroMQ on loopback",
     [](CLI::App& sub) {
       auto a = std::make_shared<SwarmArgs>();
       sub.add_option("--agents", a->agents, "Number of agents (1 … 200)")->required();
       sub.add_option("--scenario", a->scenario, "nominal | few-anchors | outside-hull | occluded")
           ->check(CLI::IsMember(uwb::sim::swarmScenarioNames()));
       sub.add_option("--duration", a->duration, "Flight duration [s] (≥ 4)");
       sub.add_option("--seed", a->seed, "Simulation seed");
       sub.add_option("--speed", a->speed, "1: sensor events in real time; max: as fast as possible")
           ->check(CLI::IsMember({"1", "max"}));
       sub.add_option("--imu-rate", a->imu_rate, "Simulated IMU rate [Hz] (50 … 1000)");
       sub.add_option("--fusion", a->fusion,
                      "extrinsic: broadcast anchors-only beliefs (default); ci: cooperative beliefs by covariance "
                      "intersection; naive: cooperative beliefs as if independent")
           ->check(CLI::IsMember({"extrinsic", "ci", "naive"}));
       sub.add_flag("--json", a->json_out, "Print one JSON object");
       sub.add_flag("--in-process", a->in_process,
                    "Run the same agents in this process in sensor time (no ZeroMQ, deterministic): overall scores only");
       sub.add_option("--out", a->out, "Write swarm_report.json and swarm_agents.csv here (atomically, at the end)");
       sub.callback([a] { runSwarm(*a); });
     }});

const bool kRegisteredAgent = uwb::app::registerCommand({"swarm-agent", "", [](CLI::App& sub) {
                                                           auto a = std::make_shared<AgentArgs>();
                                                           sub.group("");  // hidden: started by `swarm`
                                                           sub.add_option("--id", a->id)->required();
                                                           sub.add_option("--agents", a->agents)->required();
                                                           sub.add_option("--scenario", a->scenario)->required();
                                                           sub.add_option("--duration", a->duration)->required();
                                                           sub.add_option("--fusion", a->fusion)->required();
                                                           sub.add_option("--events", a->events)->required();
                                                           sub.add_option("--bus-in", a->bus_in)->required();
                                                           sub.add_option("--bus-out", a->bus_out)->required();
                                                           sub.add_option("--report", a->report)->required();
                                                           sub.callback([a] { runAgent(*a); });
                                                         }});

}  // namespace
