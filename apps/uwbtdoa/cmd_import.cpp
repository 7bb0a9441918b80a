/** @file cmd_import.cpp
 *  @brief `uwbtdoa import LOG --out FLIGHT.csv [--salvage] [--json]`: a Crazyflie uSD-card event log (cfusdlog)
 *  as a UTIL flight CSV (io/UsdImport.h; docs/io.md §6). Prints what each stream came from, counts, time span and
 *  rates; warns about streams the other commands need (TDoA, IMU, ground truth) that the log lacks.
 */
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "Command.h"
#include "InputGuards.h"
#include "uwb/io/FileAccess.h"
#include "uwb/eval/FlightSummary.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UtilCsv.h"

namespace {

using nlohmann::json;

struct Options {
  std::string log;
  std::string out;
  bool salvage = false;
  bool json = false;
};

const uwb::UsdImportReport::Source* sourceOf(const uwb::UsdImportReport& r, uwb::Stream s) {
  for (const auto& src : r.sources) {
    if (src.stream == s) return &src;
  }
  return nullptr;
}

/// What the other commands will miss.
void warnMissing(const uwb::Flight& flight, uwb::app::Warnings& warnings) {
  if (flight.tdoa.empty() && flight.twr.empty()) {
    warnings.add("no UWB measurements (estTDOA or estDistance events): nothing to localize with");
  }
  if (!flight.hasImu()) {
    warnings.add(fmt::format("no IMU ({} missing): `localize` needs estAcceleration and estGyroscope events",
                             flight.acc.empty() && flight.gyro.empty() ? "acc and gyro" : flight.acc.empty() ? "acc" : "gyro"));
  }
  if (!flight.hasGroundTruth()) {
    warnings.add("no ground truth (estPose/estPosition events): `evaluate`, `train` and the residuals of `inspect` "
                 "need a pose stream");
  }
}

void run(const Options& o) {
  uwb::checkOutputFile(o.out, "flight file", {o.log});
  uwb::UsdReadOptions read_options;
  read_options.salvage = o.salvage;
  uwb::UsdReadReport read_report;
  const uwb::UsdLog log = uwb::readUsdLog(o.log, read_options, &read_report);
  uwb::UsdImportReport report;
  report.notes = read_report.notes;
  const uwb::Flight flight = uwb::flightFromUsdLog(log, &report);
  const uwb::FlightSummary summary = uwb::summarizeFlight(flight, nullptr);

  uwb::app::Warnings warnings;
  for (const std::string& w : read_report.warnings) warnings.add(w);
  warnMissing(flight, warnings);
  for (const uwb::InputIssue& i : uwb::checkStreamRates(flight)) warnings.add(i.text());

  uwb::writeFlightCsv(flight, o.out);

  if (o.json) {
    json streams = json::object();
    for (const auto& st : summary.streams) {
      if (!st.present) continue;
      const auto* src = sourceOf(report, st.stream);
      streams[st.name] = json{{"count", st.count},        {"rate_hz", st.rate_hz},
                              {"t_first_s", st.t_first_s}, {"t_last_s", st.t_last_s},
                              {"event", src != nullptr ? src->event : ""},
                              {"fields", src != nullptr ? src->fields : ""}};
    }
    json j{{"log", o.log},
           {"out", o.out},
           {"format_version", log.version},
           {"n_bytes", read_report.n_bytes},
           {"n_events", read_report.n_events},
           {"crc_ok", read_report.crc_ok},
           {"skipped_bytes", read_report.skipped_bytes},
           {"dropped_events", read_report.dropped_events},
           {"t0_us", report.t0_us},
           {"t_start_s", summary.t_start_s},
           {"t_end_s", summary.t_end_s},
           {"duration_s", summary.duration_s},
           {"pose_has_orientation", flight.pose_has_orientation},
           {"streams", streams},
           {"notes", report.notes},
           {"warnings", warnings.list()}};
    std::cout << uwb::app::dumpJson(j, 2) << '\n';
    return;
  }
  std::cout << fmt::format("log       {} (cfusdlog version {}, {} events, {} bytes, CRC {})\n", o.log, log.version,
                           read_report.n_events, read_report.n_bytes, read_report.crc_ok ? "ok" : "mismatch, read in salvage mode");
  std::cout << fmt::format("flight    {}\n", o.out);
  std::cout << fmt::format("duration  {:.3f} s  ({:.6f} … {:.6f} s)\n\n", summary.duration_s, summary.t_start_s,
                           summary.t_end_s);
  std::cout << fmt::format("{:<6} {:>8} {:>10} {:>11} {:>11}  {}\n", "stream", "count", "rate [Hz]", "first [s]",
                           "last [s]", "from");
  for (const auto& st : summary.streams) {
    if (!st.present) continue;
    const auto* src = sourceOf(report, st.stream);
    std::cout << fmt::format("{:<6} {:>8} {:>10.1f} {:>11.6f} {:>11.6f}  {}\n", st.name, st.count, st.rate_hz,
                             st.t_first_s, st.t_last_s,
                             src != nullptr ? fmt::format("{} {{{}}}", src->event, src->fields) : "");
  }
  if (!report.notes.empty()) {
    std::cout << "\nnotes:\n";
    for (const auto& n : report.notes) std::cout << "  - " << n << '\n';
  }
}

void setup(CLI::App& sub) {
  auto o = std::make_shared<Options>();
  sub.add_option("log", o->log, "uSD-card deck event log (cfusdlog binary, format version 1 or 2)")->required();
  sub.add_option("--out,-o", o->out, "Flight CSV to write (UTIL layout)")->required();
  sub.add_flag("--salvage", o->salvage,
               "Read a log whose writing was cut (no valid CRC): keep the events up to the last complete one");
  sub.add_flag("--json", o->json, "Print exactly one JSON object on stdout");
  sub.callback([o] { run(*o); });
}

const bool kRegistered = uwb::app::registerCommand(
    {"import", "Convert a Crazyflie uSD-card event log into a UTIL flight CSV", setup});

}  // namespace
