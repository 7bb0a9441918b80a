/** @file TrajectoryCsv.cpp
 *  @brief Estimated-trajectory CSV (t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz), exact round trip.
 */
#include "uwb/io/TrajectoryCsv.h"

#include <fmt/format.h>

#include <array>
#include <cstring>
#include <string_view>

#include "CsvDetail.h"

namespace uwb {

namespace {
constexpr std::array<const char*, 14> kTrajectoryColumns{"t",  "x",     "y",     "z",     "qx", "qy", "qz",
                                                         "qw", "std_x", "std_y", "std_z", "vx", "vy", "vz"};
}  // namespace

void writeTrajectoryCsv(const Trajectory& trajectory, const std::string& path) {
  std::string out;
  out.reserve(trajectory.size() * 14 * 12 + 128);
  for (std::size_t i = 0; i < kTrajectoryColumns.size(); ++i) {
    if (i > 0) out.push_back(',');
    out += kTrajectoryColumns[i];
  }
  out.push_back('\n');
  for (const TrajectorySample& s : trajectory) {
    const double v[14] = {s.t_s,         s.w_p_b.x(),     s.w_p_b.y(),     s.w_p_b.z(),     s.w_q_b.x(),
                          s.w_q_b.y(),   s.w_q_b.z(),     s.w_q_b.w(),     s.sigma_p_m.x(), s.sigma_p_m.y(),
                          s.sigma_p_m.z(), s.w_v_b.x(),   s.w_v_b.y(),     s.w_v_b.z()};
    for (int k = 0; k < 14; ++k) {
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
  std::array<int, 14> col{};  // file column of each trajectory field
  col.fill(-1);
  std::size_t n_cols = 0;
  std::vector<std::string> names;
  Trajectory out;
  std::vector<std::string_view> cells;
  const char* b = nullptr;
  const char* e = nullptr;
  while (lines.next(b, e)) {
    const std::size_t line = lines.line();
    io_detail::trim(b, e);
    if (b == e) continue;
    io_detail::splitCells(b, e, cells);
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
      for (std::size_t f = 0; f < kTrajectoryColumns.size(); ++f) {
        if (col[f] < 0) fail(line, 0, "", fmt::format("missing column '{}' in the header", kTrajectoryColumns[f]));
      }
      n_cols = cells.size();
      continue;
    }
    if (cells.size() != n_cols) {
      fail(line, 0, "", fmt::format("row has {} fields, the header has {}", cells.size(), n_cols));
    }
    double v[14];
    for (std::size_t f = 0; f < 14; ++f) {
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
    out.push_back(s);
  }
  if (names.empty()) fail(1, 0, "", "empty file: missing header line");
  return out;
}

}  // namespace uwb
