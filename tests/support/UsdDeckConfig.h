/** @file UsdDeckConfig.h
 *  @brief The uSD-card deck's config.txt as the firmware reads it (usddeck.c: whitespace stripped, `#` starts a
 *         comment, four header lines: format version, buffer size, file name, enable at start-up; then
 *         `on:EVENT` lines, each followed by the log variables `group.name` added to that event), and a flight
 *         written as the log such a config makes the firmware write. Header-only: for tests that link uwb_io.
 */
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "uwb/io/UsdImport.h"
#include "uwb/io/UsdLog.h"

namespace uwb::test {

struct UsdDeckConfig {
  int version = 0;
  long buffer_bytes = 0;
  std::string file_prefix;
  bool enable_on_startup = false;
  std::vector<std::pair<std::string, std::vector<std::string>>> events;  ///< (event, log variables) in file order
};

/// examples/usd/config.txt of this source tree.
inline std::filesystem::path shippedUsdConfigPath() {
  return std::filesystem::path(UWB_SOURCE_DIR) / "examples" / "usd" / "config.txt";
}

inline UsdDeckConfig parseUsdDeckConfig(const std::string& text) {
  std::vector<std::string> lines;  // as f_gets_without_comments returns them; comment-only lines skipped
  std::istringstream in(text);
  for (std::string raw; std::getline(in, raw);) {
    std::string kept;
    bool comment = false;
    for (char c : raw) {
      if (c == '#') comment = true;
      if (comment || c == ' ' || c == '\t' || c == '\r') continue;
      kept.push_back(c);
    }
    const bool pure_comment = raw.find_first_not_of(" \t\r") != std::string::npos &&
                              raw[raw.find_first_not_of(" \t\r")] == '#';
    if (!pure_comment) lines.push_back(kept);
  }
  if (lines.size() < 4) throw std::invalid_argument("config.txt: fewer than the 4 header lines");
  UsdDeckConfig c;
  c.version = std::stoi(lines[0]);
  c.buffer_bytes = std::stol(lines[1]);
  c.file_prefix = lines[2];
  c.enable_on_startup = std::stoi(lines[3]) != 0;
  for (std::size_t i = 4; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.rfind("on:", 0) == 0) {
      c.events.push_back({l.substr(3), {}});
    } else if (l.size() > 3 && !c.events.empty()) {  // the firmware skips lines of 3 characters or fewer
      c.events.back().second.push_back(l);
    }
  }
  return c;
}

inline UsdDeckConfig readShippedUsdConfig() {
  std::ifstream in(shippedUsdConfigPath());
  if (!in) throw std::runtime_error("cannot read " + shippedUsdConfigPath().string());
  std::stringstream ss;
  ss << in.rdbuf();
  return parseUsdDeckConfig(ss.str());
}

/// The fields the firmware writes itself for an event (its EVENTTRIGGER payload, estimator.c), before the
/// configured log variables. Events of the import's table without a payload of their own have none.
inline std::vector<std::string> firmwarePayload(const std::string& event) {
  if (event == "estTDOA") return {"idA", "idB", "distanceDiff"};
  if (event == "estDistance") return {"id", "distance"};
  return {};
}

/// `flight` as the log the firmware writes under `config`: usdLogFromFlight's events, keeping the event types the
/// config names, each of which must carry exactly the firmware payload followed by the configured variables
/// (std::runtime_error naming the event otherwise).
inline UsdLog usdLogThroughConfig(const Flight& flight, const UsdDeckConfig& config) {
  const UsdLog all = usdLogFromFlight(flight);
  UsdLog out;
  out.version = all.version;
  out.source = all.source;
  std::vector<std::pair<std::size_t, std::size_t>> kept;  // (type in all, type in out)
  for (const auto& [event, variables] : config.events) {
    const int t = all.typeIndex(event);
    if (t < 0) continue;  // a stream the flight does not have
    const UsdEventType& type = all.types[static_cast<std::size_t>(t)];
    std::vector<std::string> expected = firmwarePayload(event);
    expected.insert(expected.end(), variables.begin(), variables.end());
    std::vector<std::pair<std::string, UsdType>> fields;
    for (const UsdField& f : type.fields) fields.emplace_back(f.name, f.type);
    std::vector<std::string> names;
    for (const auto& f : fields) names.push_back(f.first);
    if (names != expected) throw std::runtime_error("config.txt's fields of " + event + " differ from the writer's");
    kept.emplace_back(static_cast<std::size_t>(t), out.addType(type.id, type.name, fields));
  }
  // events in file order (by time, as written)
  std::vector<std::tuple<std::uint32_t, std::size_t, std::size_t>> order;  // (number, kept index, event)
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const UsdEventSeries& s = all.events[kept[k].first];
    for (std::size_t i = 0; i < s.size(); ++i) order.emplace_back(s.number[i], k, i);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [number, k, i] : order) {
    const std::size_t t = kept[k].first;
    std::vector<double> values;
    for (std::size_t f = 0; f < all.types[t].fields.size(); ++f) values.push_back(all.value(t, i, f));
    out.addEvent(kept[k].second, all.events[t].t_us[i], values);
  }
  return out;
}

}  // namespace uwb::test
