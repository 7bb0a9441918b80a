/** @file UtilCsv.cpp
 *  @brief UTIL flight-CSV reader and writer (Zhao et al., IJRR 2022, arXiv:2203.14471; docs/io.md).
 *
 *  Reader: the file is read into one buffer and parsed with std::from_chars; each stream keeps its own cursor,
 *  ends at its first empty time cell and may not resume. Units are converted once here (g → m/s², deg/s → rad/s).
 *  Writer: std::to_chars shortest representation; converted values are written as the decimal that converts back
 *  to the same double (io_detail::unscaleExactly), so read(write(read(f))) == read(f) bit for bit.
 */
#include "uwb/io/UtilCsv.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "CsvDetail.h"

namespace uwb {

namespace {

using io_detail::NumberStatus;

constexpr int kNumStreams = 8;
constexpr int kMaxFields = 8;
constexpr int kPoseQuatFirstField = 4;  ///< pose fields 0..3: t, x, y, z; 4..7: qx, qy, qz, qw

struct ColumnDef {
  const char* name;
  Stream stream;
  int field;
};

// UTIL column names. TWR first (the TWR variant starts with it), then the 27 TDoA-layout columns in file order.
constexpr std::array<ColumnDef, 30> kColumns{{
    {"t_twr", Stream::kTwr, 0},    {"anchor_id", Stream::kTwr, 1}, {"twr_range", Stream::kTwr, 2},
    {"t_tdoa", Stream::kTdoa, 0},  {"idA", Stream::kTdoa, 1},      {"idB", Stream::kTdoa, 2},
    {"tdoa_meas", Stream::kTdoa, 3},
    {"t_acc", Stream::kAcc, 0},    {"acc_x", Stream::kAcc, 1},     {"acc_y", Stream::kAcc, 2},
    {"acc_z", Stream::kAcc, 3},
    {"t_gyro", Stream::kGyro, 0},  {"gyro_x", Stream::kGyro, 1},   {"gyro_y", Stream::kGyro, 2},
    {"gyro_z", Stream::kGyro, 3},
    {"t_tof", Stream::kTof, 0},    {"tof", Stream::kTof, 1},
    {"t_flow", Stream::kFlow, 0},  {"deltaX", Stream::kFlow, 1},   {"deltaY", Stream::kFlow, 2},
    {"t_baro", Stream::kBaro, 0},  {"baro", Stream::kBaro, 1},
    {"t_pose", Stream::kPose, 0},  {"pose_x", Stream::kPose, 1},   {"pose_y", Stream::kPose, 2},
    {"pose_z", Stream::kPose, 3},  {"pose_qx", Stream::kPose, 4},  {"pose_qy", Stream::kPose, 5},
    {"pose_qz", Stream::kPose, 6}, {"pose_qw", Stream::kPose, 7},
}};

int streamIndex(Stream s) { return static_cast<int>(s); }

int numFields(Stream s) {
  switch (s) {
    case Stream::kTdoa: return 4;
    case Stream::kTwr: return 3;
    case Stream::kAcc: return 4;
    case Stream::kGyro: return 4;
    case Stream::kTof: return 2;
    case Stream::kFlow: return 3;
    case Stream::kBaro: return 2;
    case Stream::kPose: return 8;
  }
  return 0;
}

const ColumnDef* findColumn(std::string_view name) {
  for (const ColumnDef& c : kColumns) {
    if (name == c.name) return &c;
  }
  return nullptr;
}

const char* fieldName(Stream s, int field) {
  for (const ColumnDef& c : kColumns) {
    if (c.stream == s && c.field == field) return c.name;
  }
  return "?";
}

/// Where each stream's fields sit in the file: column index per field, -1 when absent.
struct Layout {
  std::array<std::array<int, kMaxFields>, kNumStreams> col;
  std::array<bool, kNumStreams> present{};
  bool pose_quat = false;

  Layout() {
    for (auto& c : col) c.fill(-1);
  }
  /// Number of fields the stream carries in this file (pose: 4 or 8).
  int fieldsOf(Stream s) const {
    if (s == Stream::kPose) return pose_quat ? 8 : 4;
    return numFields(s);
  }
};

/// Builds the layout from column names; `fail(column_index, message)` reports problems (does not return).
template <class Fail>
Layout makeLayout(const std::vector<std::string>& names, Fail&& fail) {
  Layout layout;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const ColumnDef* def = findColumn(names[i]);
    if (def == nullptr) {
      fail(i, names[i], fmt::format("unknown column '{}' (expected UTIL names such as t_tdoa, idA, idB, tdoa_meas)",
                                    names[i]));
    }
    int& slot = layout.col[streamIndex(def->stream)][def->field];
    if (slot >= 0) fail(i, names[i], fmt::format("duplicated column '{}' (also column {})", names[i], slot + 1));
    slot = static_cast<int>(i);
  }
  for (Stream s : allStreams()) {
    const auto& c = layout.col[streamIndex(s)];
    const int n_main = s == Stream::kPose ? kPoseQuatFirstField : numFields(s);
    int n_have = 0;
    for (int f = 0; f < n_main; ++f) n_have += c[f] >= 0 ? 1 : 0;
    int n_quat = 0;
    if (s == Stream::kPose) {
      for (int f = kPoseQuatFirstField; f < 8; ++f) n_quat += c[f] >= 0 ? 1 : 0;
    }
    if (n_have == 0 && n_quat == 0) continue;
    const auto first_present = [&]() {
      for (int f = 0; f < kMaxFields; ++f) {
        if (c[f] >= 0) return static_cast<std::size_t>(c[f]);
      }
      return std::size_t{0};
    };
    if (n_have != n_main) {
      for (int f = 0; f < n_main; ++f) {
        if (c[f] < 0) {
          fail(first_present(), names[first_present()],
               fmt::format("stream '{}' is incomplete: column '{}' is missing (a stream's columns must be all "
                           "present or all absent)",
                           streamName(s), fieldName(s, f)));
        }
      }
    }
    if (s == Stream::kPose && n_quat != 0 && n_quat != 4) {
      for (int f = kPoseQuatFirstField; f < 8; ++f) {
        if (c[f] < 0) {
          fail(first_present(), names[first_present()],
               fmt::format("pose quaternion is incomplete: column '{}' is missing", fieldName(s, f)));
        }
      }
    }
    layout.present[streamIndex(s)] = true;
    if (s == Stream::kPose) layout.pose_quat = n_quat == 4;
  }
  return layout;
}

/// Per-stream parsing state.
struct StreamCursor {
  bool ended = false;
  std::size_t end_line = 0;  ///< line of the first empty time cell
  double last_t = -std::numeric_limits<double>::infinity();
  std::size_t duplicates = 0;
  std::size_t count = 0;
};

}  // namespace

bool isFileQuaternionNormOk(double qx, double qy, double qz, double qw, double& norm) {
  norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  return std::abs(norm - 1.0) <= kMaxQuaternionNormError;
}

const char* streamName(Stream stream) {
  switch (stream) {
    case Stream::kTdoa: return "tdoa";
    case Stream::kTwr: return "twr";
    case Stream::kAcc: return "acc";
    case Stream::kGyro: return "gyro";
    case Stream::kTof: return "tof";
    case Stream::kFlow: return "flow";
    case Stream::kBaro: return "baro";
    case Stream::kPose: return "pose";
  }
  return "?";
}

const std::vector<Stream>& allStreams() {
  static const std::vector<Stream> kAll{Stream::kTwr,  Stream::kTdoa, Stream::kAcc,  Stream::kGyro,
                                        Stream::kTof,  Stream::kFlow, Stream::kBaro, Stream::kPose};
  return kAll;
}

std::vector<std::string> streamColumns(Stream stream) {
  std::vector<std::string> out;
  for (const ColumnDef& c : kColumns) {
    if (c.stream == stream) out.emplace_back(c.name);
  }
  return out;
}

const std::vector<std::string>& utilTdoaColumns() {
  static const std::vector<std::string> kCols = [] {
    std::vector<std::string> out;
    for (const ColumnDef& c : kColumns) {
      if (c.stream != Stream::kTwr) out.emplace_back(c.name);
    }
    return out;
  }();
  return kCols;
}

// ------------------------------------------------------------------------------------------------ reader

Flight readFlightCsv(const std::string& path, const FlightReadOptions& options, ReadReport* report) {
  const std::string text = io_detail::readWholeFile(path, "flight file");
  return parseFlightCsv(text, path, options, report);
}

namespace {

/// Throws the reader's InputError: file, line, 1-based column (0: whole line) and field name.
[[noreturn]] void failAt(const std::string& source, std::size_t line, std::size_t column, const std::string& field,
                         const std::string& message) {
  throw InputError(SourceLocation{source, line, column, field}, message);
}

bool isBlankLine(const char* b, const char* e) {
  io_detail::trim(b, e);
  return b == e;
}

/// The header: the first line that is not blank, split into column names.
struct Header {
  std::vector<std::string> names;
  std::size_t line = 0;
};

Header readHeader(io_detail::LineCursor& lines, const std::string& source) {
  const char* b = nullptr;
  const char* e = nullptr;
  bool found = false;
  while (lines.next(b, e)) {
    if (!isBlankLine(b, e)) {
      found = true;
      break;
    }
  }
  if (!found) failAt(source, lines.line() == 0 ? 1 : lines.line(), 0, "", "empty file: missing header line");
  Header h;
  h.line = lines.line();
  io_detail::forEachCell(b, e, [&](std::size_t, const char* tb, const char* te) { h.names.emplace_back(tb, te); });
  double dummy = 0.0;
  const std::string& first = h.names.front();
  if (first.empty() ||
      io_detail::parseDouble(first.data(), first.data() + first.size(), dummy) == NumberStatus::kOk) {
    failAt(source, h.line, 1, "", "missing header line: the first line holds data, expected column names");
  }
  return h;
}

/// Capacity: no stream is longer than the number of lines left (one vectorised pass over the buffer). Capped, so
/// that a file of mostly blank lines cannot make the reader reserve gigabytes; longer streams simply grow.
constexpr std::size_t kMaxReservedRows = std::size_t{1} << 21;

void reserveStreams(const Layout& layout, std::string_view rest, Flight& flight) {
  const std::size_t approx_rows = std::min(
      static_cast<std::size_t>(std::count(rest.begin(), rest.end(), '\n')) + 1, kMaxReservedRows);
  for (Stream s : allStreams()) {
    if (!layout.present[streamIndex(s)]) continue;
    switch (s) {
      case Stream::kTdoa: flight.tdoa.reserve(approx_rows); break;
      case Stream::kTwr: flight.twr.reserve(approx_rows); break;
      case Stream::kAcc: flight.acc.reserve(approx_rows); break;
      case Stream::kGyro: flight.gyro.reserve(approx_rows); break;
      case Stream::kPose: flight.pose.reserve(approx_rows); break;
      default: break;
    }
  }
}

/// Present streams in the order of their time column in the file (error order follows the row).
std::vector<Stream> streamsInFileOrder(const Layout& layout) {
  std::vector<Stream> present;
  for (Stream s : allStreams()) {
    if (layout.present[streamIndex(s)]) present.push_back(s);
  }
  std::sort(present.begin(), present.end(), [&](Stream a, Stream b) {
    return layout.col[streamIndex(a)][0] < layout.col[streamIndex(b)][0];
  });
  return present;
}

/// Parses the data rows into the flight, one stream cell group at a time; each stream keeps its own cursor.
class RowParser {
 public:
  RowParser(const std::string& source, const Header& header, const Layout& layout, const FlightReadOptions& options,
            Flight& flight)
      : source_(source), names_(header.names), layout_(layout), options_(options), flight_(flight),
        present_(streamsInFileOrder(layout)), cell_b_(names_.size()), cell_e_(names_.size()) {}

  /// One non-blank line: split it, then read each present stream's cells.
  void parseRow(std::size_t line, const char* b, const char* e) {
    line_ = line;
    const std::size_t n_cols = names_.size();
    const std::size_t n = io_detail::forEachCell(b, e, [&](std::size_t i, const char* tb, const char* te) {
      if (i < n_cols) {
        cell_b_[i] = tb;
        cell_e_[i] = te;
      }
    });
    if (n != n_cols) {
      fail(std::min(n, n_cols) + (n > n_cols ? 1 : 0), "", fmt::format("row has {} fields, the header has {}", n, n_cols));
    }
    for (Stream s : present_) parseStream(s);
  }

  const std::vector<Stream>& present() const { return present_; }
  const StreamCursor& cursor(Stream s) const { return cursors_[streamIndex(s)]; }

 private:
  [[noreturn]] void fail(std::size_t column, const std::string& field, const std::string& message) const {
    failAt(source_, line_, column, field, message);
  }
  bool empty(int c) const { return cell_b_[c] == cell_e_[c]; }
  std::string_view cell(int c) const { return {cell_b_[c], static_cast<std::size_t>(cell_e_[c] - cell_b_[c])}; }

  void parseStream(Stream s) {
    const int si = streamIndex(s);
    const auto& col = layout_.col[si];
    const int nf = layout_.fieldsOf(s);
    StreamCursor& cur = cursors_[si];
    if (empty(col[0])) {
      endStream(s, cur);
      return;
    }
    if (cur.ended) {
      fail(col[0] + 1, names_[col[0]],
           fmt::format("stream '{}' continues after it ended (its time cell was empty on line {})", streamName(s),
                       cur.end_line));
    }
    double v[kMaxFields];
    for (int f = 0; f < nf; ++f) {
      const int c = col[f];
      if (empty(c)) {
        fail(c + 1, names_[c], fmt::format("partly filled row of stream '{}': '{}' is empty", streamName(s), names_[c]));
      }
      const NumberStatus st = io_detail::parseDouble(cell_b_[c], cell_e_[c], v[f]);
      if (st != NumberStatus::kOk) fail(c + 1, names_[c], fmt::format("{}: '{}'", io_detail::describe(st), cell(c)));
    }
    checkTimeOrder(s, cur, v[0]);
    appendSample(s, v);
  }

  /// An empty time cell ends the stream; its other cells must be empty too.
  void endStream(Stream s, StreamCursor& cur) {
    const auto& col = layout_.col[streamIndex(s)];
    for (int f = 1; f < layout_.fieldsOf(s); ++f) {
      const int c = col[f];
      if (!empty(c)) {
        fail(c + 1, names_[c],
             fmt::format("partly filled row of stream '{}': '{}' is empty but '{}' is not", streamName(s),
                         names_[col[0]], names_[c]));
      }
    }
    if (!cur.ended) {
      cur.ended = true;
      cur.end_line = line_;
    }
  }

  void checkTimeOrder(Stream s, StreamCursor& cur, double t) {
    if (t < cur.last_t) {
      const int c = layout_.col[streamIndex(s)][0];
      fail(c + 1, names_[c], fmt::format("time goes backwards in stream '{}': {} after {}", streamName(s), t, cur.last_t));
    }
    if (t == cur.last_t) ++cur.duplicates;
    cur.last_t = t;
    ++cur.count;
  }

  /// Field f of stream s as an anchor id: an integer in [0, kMaxAnchorId], in the survey when one is given.
  int anchorId(Stream s, int f, double x) const {
    const int c = layout_.col[streamIndex(s)][f];
    if (x != std::floor(x) || x < 0 || x > kMaxAnchorId) {
      fail(c + 1, names_[c], fmt::format("anchor id must be an integer in [0, {}]: '{}'", kMaxAnchorId, cell(c)));
    }
    const int id = static_cast<int>(x);
    if (options_.survey != nullptr && !options_.survey->contains(id)) {
      fail(c + 1, names_[c],
           fmt::format("anchor id {} has no entry in the survey{}", id,
                       options_.survey->source.empty() ? std::string() : " " + options_.survey->source));
    }
    return id;
  }

  /// Stores one sample, converting units once (acc g → m/s², gyro deg/s → rad/s).
  void appendSample(Stream s, const double* v) {
    const double t = v[0];
    switch (s) {
      case Stream::kTdoa: {
        const int id_a = anchorId(s, 1, v[1]), id_b = anchorId(s, 2, v[2]);
        if (id_a == id_b) {  // a TDoA of an anchor against itself is no measurement (h = 0 for every position)
          const int c = layout_.col[streamIndex(s)][2];
          fail(c + 1, names_[c], fmt::format("idA and idB are the same anchor ({}): a TDoA needs two anchors", id_a));
        }
        flight_.tdoa.push_back({t, id_a, id_b, v[3]});
        break;
      }
      case Stream::kTwr: flight_.twr.push_back({t, anchorId(s, 1, v[1]), v[2]}); break;
      case Stream::kAcc:
        flight_.acc.push_back({t, Vec3(v[1] * kGravity_mps2, v[2] * kGravity_mps2, v[3] * kGravity_mps2)});
        break;
      case Stream::kGyro: flight_.gyro.push_back({t, Vec3(v[1] * kDegToRad, v[2] * kDegToRad, v[3] * kDegToRad)}); break;
      case Stream::kTof: flight_.tof.push_back({t, v[1]}); break;
      case Stream::kFlow: flight_.flow.push_back({t, v[1], v[2]}); break;
      case Stream::kBaro: flight_.baro.push_back({t, v[1]}); break;
      case Stream::kPose: flight_.pose.push_back(poseSample(v)); break;
    }
  }

  PoseSample poseSample(const double* v) const {
    PoseSample ps;
    ps.t_s = v[0];
    ps.w_p_b = Vec3(v[1], v[2], v[3]);
    if (layout_.pose_quat) {
      double norm = 0.0;
      if (!isFileQuaternionNormOk(v[4], v[5], v[6], v[7], norm)) {
        const int c = layout_.col[streamIndex(Stream::kPose)][kPoseQuatFirstField];
        fail(c + 1, names_[c],
             fmt::format("pose quaternion is far from unit norm: |q| = {:.6g} (tolerance {})", norm,
                         kMaxQuaternionNormError));
      }
      ps.w_q_b = Quat(v[7], v[4], v[5], v[6]);  // Eigen order: w, x, y, z
    }
    return ps;
  }

  const std::string& source_;
  const std::vector<std::string>& names_;
  const Layout& layout_;
  const FlightReadOptions& options_;
  Flight& flight_;
  std::vector<Stream> present_;
  std::array<StreamCursor, kNumStreams> cursors_{};
  std::vector<const char*> cell_b_;
  std::vector<const char*> cell_e_;
  std::size_t line_ = 0;
};

/// Tolerated oddities, counted in the report.
void addNotes(const RowParser& rows, const Layout& layout, std::size_t blank_lines, ReadReport& rep) {
  if (blank_lines > 0) rep.notes.push_back(fmt::format("{} blank line(s) inside the data skipped", blank_lines));
  for (Stream s : rows.present()) {
    const StreamCursor& cur = rows.cursor(s);
    if (cur.duplicates > 0) {
      rep.notes.push_back(fmt::format("{} duplicate timestamp(s) in stream {}", cur.duplicates, streamName(s)));
    }
    if (cur.count == 0) rep.notes.push_back(fmt::format("stream {}: columns present but no samples", streamName(s)));
  }
  if (layout.present[streamIndex(Stream::kPose)] && !layout.pose_quat) {
    rep.notes.push_back("pose carries position only (no quaternion columns)");
  }
}

/// Streams the caller requires must be present and hold samples.
void checkRequired(const std::string& source, const Header& header, const Layout& layout, const RowParser& rows,
                   const FlightReadOptions& options) {
  for (Stream s : options.required) {
    const int si = streamIndex(s);
    if (!layout.present[si]) {
      failAt(source, header.line, 0, "",
             fmt::format("required stream '{}' is missing: no '{}' column in the header", streamName(s),
                         fieldName(s, 0)));
    }
    if (rows.cursor(s).count == 0) {
      const int c = layout.col[si][0];
      failAt(source, header.line + 1, c + 1, header.names[c],
             fmt::format("required stream '{}' has no samples", streamName(s)));
    }
  }
}

}  // namespace

Flight parseFlightCsv(std::string_view text, const std::string& source, const FlightReadOptions& options,
                      ReadReport* report) {
  Flight flight;
  flight.source = source;
  ReadReport local_report;
  ReadReport& rep = report != nullptr ? *report : local_report;
  rep = ReadReport{};
  rep.n_bytes = text.size();

  io_detail::LineCursor lines(text);  // skips a UTF-8 BOM, strips CR
  const Header header = readHeader(lines, source);
  const Layout layout = makeLayout(header.names, [&](std::size_t i, const std::string& name, const std::string& msg) {
    failAt(source, header.line, i + 1, name, msg);
  });
  flight.columns = header.names;
  flight.pose_has_orientation = layout.present[streamIndex(Stream::kPose)] && layout.pose_quat;
  reserveStreams(layout, lines.rest(), flight);

  RowParser rows(source, header, layout, options, flight);
  std::size_t blank_lines = 0;
  std::size_t pending_blank = 0;  // blank lines not yet known to be trailing (tolerated unless inside the data)
  const char* b = nullptr;
  const char* e = nullptr;
  while (lines.next(b, e)) {
    if (isBlankLine(b, e)) {
      ++pending_blank;
      continue;
    }
    blank_lines += pending_blank;
    pending_blank = 0;
    ++rep.n_rows;
    rows.parseRow(lines.line(), b, e);
  }
  addNotes(rows, layout, blank_lines, rep);
  checkRequired(source, header, layout, rows, options);
  return flight;
}

// ------------------------------------------------------------------------------------------------ writer

std::size_t io_detail::streamSize(const Flight& f, Stream s) {
  switch (s) {
    case Stream::kTdoa: return f.tdoa.size();
    case Stream::kTwr: return f.twr.size();
    case Stream::kAcc: return f.acc.size();
    case Stream::kGyro: return f.gyro.size();
    case Stream::kTof: return f.tof.size();
    case Stream::kFlow: return f.flow.size();
    case Stream::kBaro: return f.baro.size();
    case Stream::kPose: return f.pose.size();
  }
  return 0;
}

namespace {

std::vector<std::string> defaultColumns(const Flight& flight) {
  std::vector<std::string> cols;
  if (!flight.twr.empty()) {
    for (auto& c : streamColumns(Stream::kTwr)) cols.push_back(c);
  }
  for (const auto& c : utilTdoaColumns()) {
    if (!flight.pose_has_orientation && c.rfind("pose_q", 0) == 0) continue;
    cols.push_back(c);
  }
  return cols;
}

/// The number of rows the flight needs; throws when a stream with samples has no column or the pose quaternion
/// columns disagree with flight.pose_has_orientation.
std::size_t checkedRowCount(const Flight& flight, const Layout& layout) {
  std::size_t n_rows = 0;
  for (Stream s : allStreams()) {
    const std::size_t n = io_detail::streamSize(flight, s);
    if (n > 0 && !layout.present[streamIndex(s)]) {
      throw std::invalid_argument(fmt::format(
          "writeFlightCsv: stream '{}' holds {} samples but flight.columns has none of its columns", streamName(s), n));
    }
    n_rows = std::max(n_rows, n);
  }
  if (layout.present[streamIndex(Stream::kPose)] && layout.pose_quat != flight.pose_has_orientation &&
      !flight.pose.empty()) {
    throw std::invalid_argument(
        "writeFlightCsv: flight.columns and flight.pose_has_orientation disagree about the pose quaternion");
  }
  return n_rows;
}

/// Appends field f of sample r of stream s in the file's units (g, deg/s for the IMU).
void appendCell(std::string& out, const Flight& flight, Stream s, int f, std::size_t r) {
  using io_detail::appendDouble;
  using io_detail::appendInt;
  using io_detail::unscaleExactly;
  switch (s) {
    case Stream::kTdoa: {
      const TdoaMeasurement& m = flight.tdoa[r];
      if (f == 0) appendDouble(out, m.t_s);
      else if (f == 1) appendInt(out, m.id_a);
      else if (f == 2) appendInt(out, m.id_b);
      else appendDouble(out, m.tdoa_m);
      break;
    }
    case Stream::kTwr: {
      const TwrMeasurement& m = flight.twr[r];
      if (f == 0) appendDouble(out, m.t_s);
      else if (f == 1) appendInt(out, m.anchor_id);
      else appendDouble(out, m.range_m);
      break;
    }
    case Stream::kAcc:
    case Stream::kGyro: {
      const bool acc = s == Stream::kAcc;
      const ImuSample& m = acc ? flight.acc[r] : flight.gyro[r];
      if (f == 0) appendDouble(out, m.t_s);
      else appendDouble(out, unscaleExactly(m.b_value[f - 1], acc ? kGravity_mps2 : kDegToRad));
      break;
    }
    case Stream::kTof: appendDouble(out, f == 0 ? flight.tof[r].t_s : flight.tof[r].value); break;
    case Stream::kBaro: appendDouble(out, f == 0 ? flight.baro[r].t_s : flight.baro[r].value); break;
    case Stream::kFlow: {
      const FlowSample& m = flight.flow[r];
      appendDouble(out, f == 0 ? m.t_s : f == 1 ? m.delta_x : m.delta_y);
      break;
    }
    case Stream::kPose: {
      const PoseSample& m = flight.pose[r];
      switch (f) {
        case 0: appendDouble(out, m.t_s); break;
        case 1: appendDouble(out, m.w_p_b.x()); break;
        case 2: appendDouble(out, m.w_p_b.y()); break;
        case 3: appendDouble(out, m.w_p_b.z()); break;
        case 4: appendDouble(out, m.w_q_b.x()); break;
        case 5: appendDouble(out, m.w_q_b.y()); break;
        case 6: appendDouble(out, m.w_q_b.z()); break;
        default: appendDouble(out, m.w_q_b.w()); break;
      }
      break;
    }
  }
}

}  // namespace

std::string formatFlightCsv(const Flight& flight) {
  const std::vector<std::string> names = flight.columns.empty() ? defaultColumns(flight) : flight.columns;
  const Layout layout = makeLayout(names, [](std::size_t i, const std::string&, const std::string& msg) {
    throw std::invalid_argument(fmt::format("writeFlightCsv: flight.columns[{}]: {}", i, msg));
  });
  const std::size_t n_rows = checkedRowCount(flight, layout);

  // Column → (stream, field).
  struct Slot {
    Stream stream;
    int field;
  };
  std::vector<Slot> slots(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const ColumnDef* d = findColumn(names[i]);
    slots[i] = {d->stream, d->field};
  }

  std::string out;
  out.reserve(n_rows * names.size() * 11 + 512);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out.push_back(',');
    out += names[i];
  }
  out.push_back('\n');
  for (std::size_t r = 0; r < n_rows; ++r) {
    for (std::size_t i = 0; i < slots.size(); ++i) {
      if (i > 0) out.push_back(',');
      const auto [s, f] = slots[i];
      if (r < io_detail::streamSize(flight, s)) appendCell(out, flight, s, f, r);
    }
    out.push_back('\n');
  }
  return out;
}

void writeFlightCsv(const Flight& flight, const std::string& path) {
  io_detail::writeWholeFile(path, formatFlightCsv(flight), "flight file");
}

}  // namespace uwb
