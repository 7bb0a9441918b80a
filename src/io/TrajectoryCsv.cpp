/** @file TrajectoryCsv.cpp
 *  @brief Estimated-trajectory CSV (t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz[,acc_bias_*,gyro_bias_*]), exact
 *         round trip.
 */
#include "uwb/io/TrajectoryCsv.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <string_view>

#include "CsvDetail.h"

namespace uwb {

namespace {
constexpr std::size_t kRequired = 14;  // the columns every trajectory file has; the bias columns are optional together
constexpr std::size_t kAll = 20;
constexpr std::array<const char*, kAll> kTrajectoryColumns{
    "t",     "x",     "y",     "z",  "qx", "qy", "qz", "qw",
    "std_x", "std_y", "std_z", "vx", "vy", "vz",
    "acc_bias_x",  "acc_bias_y",  "acc_bias_z",
    "gyro_bias_x", "gyro_bias_y", "gyro_bias_z"};
}  // namespace

void writeTrajectoryCsv(const Trajectory& trajectory, const std::string& path) {
  // the bias columns only when every sample has its biases (a column is never partly empty)
  const bool with_bias = !trajectory.empty() && std::all_of(trajectory.begin(), trajectory.end(),
                                                            [](const TrajectorySample& s) { return s.hasImuBias(); });
  const std::size_t n_cols = with_bias ? kAll : kRequired;
  std::string out;
  out.reserve(trajectory.size() * n_cols * 12 + 256);
  for (std::size_t i = 0; i < n_cols; ++i) {
    if (i > 0) out.push_back(',');
    out += kTrajectoryColumns[i];
  }
  out.push_back('\n');
  for (const TrajectorySample& s : trajectory) {
    const double v[kAll] = {s.t_s,           s.w_p_b.x(),      s.w_p_b.y(),      s.w_p_b.z(),
                            s.w_q_b.x(),     s.w_q_b.y(),      s.w_q_b.z(),      s.w_q_b.w(),
                            s.sigma_p_m.x(), s.sigma_p_m.y(),  s.sigma_p_m.z(),
                            s.w_v_b.x(),     s.w_v_b.y(),      s.w_v_b.z(),
                            s.b_acc_bias.x(), s.b_acc_bias.y(), s.b_acc_bias.z(),
                            s.b_gyro_bias.x(), s.b_gyro_bias.y(), s.b_gyro_bias.z()};
    for (std::size_t k = 0; k < n_cols; ++k) {
      if (k > 0) out.push_back(',');
      io_detail::appendDouble(out, v[k]);
    }
    out.push_back('\n');
  }
  io_detail::writeWholeFile(path, out, "trajectory file");
}

Trajectory readTrajectoryCsv(const std::string& path) {
  return parseTrajectoryCsv(io_detail::readWholeFile(path, "trajectory file"), path);
}

Trajectory parseTrajectoryCsv(std::string_view text, const std::string& path) {
  const auto fail = [&](std::size_t line, std::size_t column, const std::string& field, const std::string& msg) {
    throw InputError(SourceLocation{path, line, column, field}, msg);
  };
  io_detail::LineCursor lines(text);
  std::array<int, kAll> col{};  // file column of each trajectory field
  col.fill(-1);
  std::size_t n_cols = 0;
  bool with_bias = false;
  std::vector<std::string> names;
  Trajectory out;
  std::vector<std::string_view> cells;
  while (io_detail::nextCells(lines, cells, io_detail::HashComments::kData)) {
    const std::size_t line = lines.line();
    if (names.empty()) {  // header
      for (std::size_t i = 0; i < cells.size(); ++i) {
        names.emplace_back(cells[i]);
        bool known = false;
        for (std::size_t f = 0; f < kTrajectoryColumns.size(); ++f) {
          if (names.back() == kTrajectoryColumns[f]) {
            if (col[f] >= 0) fail(line, i + 1, names.back(), fmt::format("duplicated column '{}'", names.back()));
            col[f] = static_cast<int>(i);
            known = true;
          }
        }
        if (!known) fail(line, i + 1, names.back(), fmt::format("unknown column '{}'", names.back()));
      }
      // the bias columns are all there or none (a file of the 14 columns reads as NaN biases)
      with_bias = std::any_of(col.begin() + kRequired, col.end(), [](int c) { return c >= 0; });
      for (std::size_t f = 0; f < (with_bias ? kAll : kRequired); ++f) {
        if (col[f] < 0) fail(line, 0, "", fmt::format("missing column '{}' in the header", kTrajectoryColumns[f]));
      }
      n_cols = cells.size();
      continue;
    }
    if (cells.size() != n_cols) {
      fail(line, 0, "", fmt::format("row has {} fields, the header has {}", cells.size(), n_cols));
    }
    double v[kAll];
    for (std::size_t f = 0; f < (with_bias ? kAll : kRequired); ++f) {
      const std::string_view cell = cells[static_cast<std::size_t>(col[f])];
      const auto st = io_detail::parseDouble(cell.data(), cell.data() + cell.size(), v[f]);
      if (st != io_detail::NumberStatus::kOk) {
        fail(line, static_cast<std::size_t>(col[f]) + 1, kTrajectoryColumns[f],
             fmt::format("{}: '{}'", io_detail::describe(st), cell));
      }
    }
    if (!out.empty() && v[0] < out.back().t_s) {
      fail(line, static_cast<std::size_t>(col[0]) + 1, "t", fmt::format("time goes backwards: {} after {}", v[0],
                                                                        out.back().t_s));
    }
    TrajectorySample s;
    s.t_s = v[0];
    s.w_p_b = Vec3(v[1], v[2], v[3]);
    s.w_q_b = Quat(v[7], v[4], v[5], v[6]);
    s.sigma_p_m = Vec3(v[8], v[9], v[10]);
    s.w_v_b = Vec3(v[11], v[12], v[13]);
    if (with_bias) {
      s.b_acc_bias = Vec3(v[14], v[15], v[16]);
      s.b_gyro_bias = Vec3(v[17], v[18], v[19]);
    }
    out.push_back(s);
  }
  if (names.empty()) fail(1, 0, "", "empty file: missing header line");
  return out;
}

namespace {
constexpr std::array<const char*, 8> kTumColumns{"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
}  // namespace

std::string formatTrajectoryTum(const Trajectory& trajectory) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  out.reserve(trajectory.size() * 8 * 20 + out.size());
  for (const TrajectorySample& s : trajectory) {
    const double v[8] = {s.t_s,       s.w_p_b.x(), s.w_p_b.y(), s.w_p_b.z(),
                         s.w_q_b.x(), s.w_q_b.y(), s.w_q_b.z(), s.w_q_b.w()};
    for (std::size_t k = 0; k < 8; ++k) {
      if (k > 0) out.push_back(' ');
      io_detail::appendDouble(out, v[k]);
    }
    out.push_back('\n');
  }
  return out;
}

void writeTrajectoryTum(const Trajectory& trajectory, const std::string& path) {
  io_detail::writeWholeFile(path, formatTrajectoryTum(trajectory), "TUM trajectory file");
}

Trajectory readTrajectoryTum(const std::string& path) {
  return parseTrajectoryTum(io_detail::readWholeFile(path, "TUM trajectory file"), path);
}

Trajectory parseTrajectoryTum(std::string_view text, const std::string& path) {
  io_detail::LineCursor lines(text);
  Trajectory out;
  const char* b = nullptr;
  const char* e = nullptr;
  while (lines.next(b, e)) {
    const std::size_t line = lines.line();
    io_detail::trim(b, e);
    if (b == e || *b == '#') continue;
    double v[8];
    std::size_t n = 0;
    const char* p = b;
    while (p < e) {
      const char* q = p;
      while (q < e && !io_detail::isBlank(*q)) ++q;
      if (n == 8) {
        throw InputError(SourceLocation{path, line, n + 1, ""}, "more than 8 numbers (timestamp tx ty tz qx qy qz qw)");
      }
      const auto st = io_detail::parseDouble(p, q, v[n]);
      if (st != io_detail::NumberStatus::kOk) {
        throw InputError(SourceLocation{path, line, n + 1, kTumColumns[n]},
                         fmt::format("{}: '{}'", io_detail::describe(st), std::string_view(p, static_cast<std::size_t>(q - p))));
      }
      ++n;
      p = q;
      while (p < e && io_detail::isBlank(*p)) ++p;
    }
    if (n != 8) {
      throw InputError(SourceLocation{path, line, n + 1, n < 8 ? kTumColumns[n] : ""},
                       fmt::format("{} numbers, expected 8 (timestamp tx ty tz qx qy qz qw)", n));
    }
    TrajectorySample s;
    s.t_s = v[0];
    s.w_p_b = Vec3(v[1], v[2], v[3]);
    s.w_q_b = Quat(v[7], v[4], v[5], v[6]);
    out.push_back(s);
  }
  return out;
}

}  // namespace uwb
