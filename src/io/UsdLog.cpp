/** @file UsdLog.cpp
 *  @brief The cfusdlog reader and writer (format in io/UsdLog.h and docs/io.md §6).
 */
#include "uwb/io/UsdLog.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"

namespace uwb {

namespace {

constexpr std::uint8_t kMagic = 0xBC;
constexpr std::size_t kCrcBytes = 4;
constexpr std::size_t kPreambleBytes = 5;  // magic, version, number of event types
/// Salvage: the deck writes its events in time order (all types on one clock), so an event more than this behind the
/// latest stamp of the log belongs to another time base (a zeroed or damaged block) [µs].
constexpr std::uint64_t kMaxStampLag_us = 1'000'000;
/// Salvage: an event further ahead of the latest stamp is kept only if the events after it confirm the jump [µs].
constexpr std::uint64_t kMaxStampLead_us = 10'000'000;
/// Salvage: events that must follow in a valid chain (declared ids, whole payloads, plausible stamps) at a place
/// where reading resumes after damage, and after a stamp that jumps ahead.
constexpr std::size_t kResyncChain = 4;

std::size_t timestampBytes(int version) { return version == 1 ? 4 : 8; }

bool isUsdType(char c) {
  switch (c) {
    case 'B': case 'b': case 'H': case 'h': case 'I': case 'i': case 'f': case 'e': return true;
    default: return false;
  }
}

std::uint64_t readLe(const std::uint8_t* p, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = n; i-- > 0;) v = (v << 8) | p[i];
  return v;
}

void appendLe(std::string& out, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

/// IEEE 754 binary16 → double (exact).
double halfToDouble(std::uint16_t h) {
  const int sign = (h >> 15) & 1;
  const int exponent = (h >> 10) & 0x1F;
  const int mantissa = h & 0x3FF;
  double v = 0.0;
  if (exponent == 0) {
    v = std::ldexp(static_cast<double>(mantissa), -24);  // subnormal
  } else if (exponent == 0x1F) {
    v = mantissa == 0 ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::quiet_NaN();
  } else {
    v = std::ldexp(static_cast<double>(mantissa | 0x400), exponent - 25);
  }
  return sign != 0 ? -v : v;
}

/// double → IEEE 754 binary16, rounded to nearest even (overflow → ±Inf).
std::uint16_t doubleToHalf(double x) {
  const std::uint16_t sign = std::signbit(x) ? 0x8000 : 0;
  if (std::isnan(x)) return 0x7E00;
  const double a = std::abs(x);
  if (a >= 65520.0) return sign | 0x7C00;  // rounds past the largest half (65504)
  if (a < std::ldexp(1.0, -14)) {          // subnormal range: units of 2^-24
    const double units = std::nearbyint(a * std::ldexp(1.0, 24));
    return sign | static_cast<std::uint16_t>(units);  // 1024 units carries into the smallest normal exactly
  }
  int e = 0;
  const double m = std::frexp(a, &e);  // a = m · 2^e, m ∈ [0.5, 1)
  double significand = std::nearbyint(m * 2048.0);  // 11 bits incl. the implicit one
  if (significand >= 2048.0) {
    significand /= 2.0;
    ++e;
  }
  const int biased = e - 1 + 15;
  if (biased >= 0x1F) return sign | 0x7C00;
  return sign | static_cast<std::uint16_t>((biased << 10) | (static_cast<int>(significand) & 0x3FF));
}

const std::array<std::uint32_t, 256>& crcTable() {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  return table;
}

/// Parses the file; one instance per call.
class Parser {
 public:
  Parser(std::string_view bytes, const std::string& source, const UsdReadOptions& options, UsdReadReport& report)
      : p_(reinterpret_cast<const std::uint8_t*>(bytes.data())), n_(bytes.size()), options_(options), report_(report) {
    log_.source = source;
  }

  UsdLog run() {
    report_.n_bytes = n_;
    readPreamble();
    checkCrc();
    readHeader();
    readEvents();
    return std::move(log_);
  }

 private:
  [[noreturn]] void failAt(std::size_t byte, const std::string& field, const std::string& what) const {
    throw InputError(fmt::format("{}: byte {} ({}): {}", log_.source, byte, field, what));
  }
  [[noreturn]] void failEvent(std::size_t byte, std::size_t event, const std::string& field,
                              const std::string& what) const {
    throw InputError(fmt::format("{}: byte {}, event {} ({}): {}", log_.source, byte, event, field, what));
  }

  void readPreamble() {
    if (n_ == 0) failAt(0, "magic", "empty file; expected a uSD-card deck event log (first byte 0xBC)");
    if (p_[0] != kMagic) {
      failAt(0, "magic", fmt::format("bad magic byte 0x{:02X}; expected 0xBC (not a uSD-card deck event log)", p_[0]));
    }
    if (n_ < kPreambleBytes) failAt(n_, "version", "file ends inside the header");
    const auto version = static_cast<int>(readLe(p_ + 1, 2));
    if (version != 1 && version != 2) {
      failAt(1, "version", fmt::format("unsupported format version {} (this reader knows versions 1 and 2)", version));
    }
    log_.version = version;
    num_types_ = static_cast<std::size_t>(readLe(p_ + 3, 2));
  }

  void checkCrc() {
    end_ = n_;
    if (n_ >= kPreambleBytes + kCrcBytes) {
      const auto stored = static_cast<std::uint32_t>(readLe(p_ + n_ - kCrcBytes, kCrcBytes));
      const std::uint32_t computed =
          crc32(std::string_view(reinterpret_cast<const char*>(p_), n_ - kCrcBytes));
      report_.crc_ok = stored == computed;
      if (report_.crc_ok) {
        end_ = n_ - kCrcBytes;
        return;
      }
      if (!options_.salvage) {
        failAt(n_ - kCrcBytes, "crc",
               fmt::format("CRC mismatch: stored 0x{:08X}, computed 0x{:08X} (the file is damaged, or its writing "
                           "was cut; salvage mode, `uwbtdoa import --salvage`, reads the events up to the last complete one)",
                           stored, computed));
      }
      report_.notes.push_back(fmt::format("CRC mismatch (stored 0x{:08X}, computed 0x{:08X}): read in salvage mode, "
                                          "the last 4 bytes are read as events",
                                          stored, computed));
      return;
    }
    if (!options_.salvage) failAt(n_, "crc", "file too short to hold the CRC trailer");
    report_.notes.push_back("file too short to hold the CRC trailer: read in salvage mode");
  }

  /// NUL-terminated string at pos_; advances past the NUL.
  std::string cString(const std::string& field) {
    const std::size_t start = pos_;
    const auto* nul = static_cast<const std::uint8_t*>(std::memchr(p_ + pos_, 0, end_ - pos_));
    if (nul == nullptr) failAt(start, field, "unterminated string (no NUL byte before the end of the header)");
    pos_ = static_cast<std::size_t>(nul - p_) + 1;
    return {reinterpret_cast<const char*>(p_ + start), static_cast<std::size_t>(nul - (p_ + start))};
  }

  std::uint64_t headerInt(std::size_t bytes, const std::string& field) {
    if (end_ - pos_ < bytes) failAt(pos_, field, "file ends inside the header");
    const std::uint64_t v = readLe(p_ + pos_, bytes);
    pos_ += bytes;
    return v;
  }

  void readHeader() {
    pos_ = kPreambleBytes;
    for (std::size_t i = 0; i < num_types_; ++i) {
      const std::size_t type_start = pos_;
      const std::string where = fmt::format("event type {}", i);
      const auto id = static_cast<std::uint16_t>(headerInt(2, where + " id"));
      std::string name = cString(where + " name");
      if (name.empty()) failAt(type_start + 2, where + " name", "empty event-type name");
      const std::size_t n_fields = headerInt(2, name + " field count");
      std::vector<std::pair<std::string, UsdType>> fields;
      for (std::size_t f = 0; f < n_fields; ++f) {
        const std::size_t field_start = pos_;
        const std::string desc = cString(fmt::format("{} field {}", name, f));
        const std::size_t len = desc.size();
        if (len < 4 || desc[len - 1] != ')' || desc[len - 3] != '(' || !isUsdType(desc[len - 2])) {
          failAt(field_start, fmt::format("{} field {}", name, f),
                 fmt::format("'{}' is not name(T) with T one of B b H h I i f e", desc));
        }
        fields.emplace_back(desc.substr(0, len - 3), static_cast<UsdType>(desc[len - 2]));
      }
      try {
        log_.addType(id, name, fields);
      } catch (const std::invalid_argument& e) {
        failAt(type_start, name, e.what());
      }
    }
    ids_.reserve(log_.types.size());
    for (std::size_t i = 0; i < log_.types.size(); ++i) ids_.emplace_back(log_.types[i].id, i);
    std::sort(ids_.begin(), ids_.end());
    duplicates_.assign(log_.types.size(), 0);
  }

  /// Type index of event id `id`, or -1.
  int typeOf(std::uint16_t id) const {
    const auto it = std::lower_bound(ids_.begin(), ids_.end(), std::make_pair(id, std::size_t{0}));
    return it == ids_.end() || it->first != id ? -1 : static_cast<int>(it->second);
  }

  /// The event at byte q, if it is whole: its type and stamp [µs] and the byte after it.
  struct Peek {
    std::size_t type = 0, next = 0;
    std::uint64_t t_us = 0;
  };
  std::optional<Peek> peek(std::size_t q) const {
    const std::size_t ts_bytes = timestampBytes(log_.version);
    if (q >= end_ || end_ - q < 2 + ts_bytes) return std::nullopt;
    const int type = typeOf(static_cast<std::uint16_t>(readLe(p_ + q, 2)));
    if (type < 0) return std::nullopt;
    const std::size_t payload = log_.types[static_cast<std::size_t>(type)].payload_bytes;
    if (end_ - q - 2 - ts_bytes < payload) return std::nullopt;
    std::uint64_t ts = readLe(p_ + q + 2, ts_bytes);
    if (log_.version == 1) ts *= 1000;
    return Peek{static_cast<std::size_t>(type), q + 2 + ts_bytes + payload, ts};
  }

  /// Salvage: true when kResyncChain whole events start at byte q (or fewer that end exactly at the end of the
  /// events), each of a declared id, stamped on the clock of the log so far (t_ref_us: not more than kMaxStampLag_us
  /// before it), and within kMaxStampLead_us of each other.
  bool chainAt(std::size_t q, std::uint64_t t_ref_us) const {
    std::uint64_t t_prev = 0;
    for (std::size_t k = 0; k < kResyncChain; ++k) {
      if (q == end_) return k > 0;
      const std::optional<Peek> e = peek(q);
      if (!e) return false;
      if (have_stamp_ && e->t_us + kMaxStampLag_us < t_ref_us) return false;
      if (k > 0 && (e->t_us + kMaxStampLag_us < t_prev || e->t_us > t_prev + kMaxStampLead_us)) return false;
      t_prev = std::max(t_prev, e->t_us);
      q = e->next;
    }
    return true;
  }

  /// Salvage: the next byte after `start` where a valid chain of events begins (end_ when none does).
  std::size_t resync(std::size_t start) const {
    for (std::size_t q = start + 1; q < end_; ++q)
      if (chainAt(q, t_latest_us_)) return q;
    return end_;
  }

  /// Salvage: the event kept just before damage may hold damaged bytes in its payload: it goes too.
  void dropLastKept() {
    if (last_type_ < 0) return;
    UsdEventSeries& s = log_.events[static_cast<std::size_t>(last_type_)];
    s.t_us.pop_back();
    s.offset.pop_back();
    s.number.pop_back();
    s.payload.resize(s.payload.size() - log_.types[static_cast<std::size_t>(last_type_)].payload_bytes);
    ++n_before_damage_;
    last_type_ = -1;
  }

  /// Salvage: counts and notes an event dropped because its stamp jumps (and drops the event before it).
  void dropJump(std::size_t type, std::uint64_t ts, bool back) {
    dropLastKept();
    ++n_jump_dropped_;
    if (n_jump_dropped_ == 1)
      first_jump_ = fmt::format("the first, {} at {:.6f} s, {} the log's clock at {:.6f} s", log_.types[type].name,
                                static_cast<double>(ts) * 1e-6, back ? "is behind" : "jumps ahead of",
                                static_cast<double>(t_latest_us_) * 1e-6);
  }

  void readEvents() {
    const std::size_t ts_bytes = timestampBytes(log_.version);
    std::size_t number = 0;
    if (n_ > std::numeric_limits<std::uint32_t>::max()) failAt(0, "size", "file larger than 4 GiB");
    while (pos_ < end_) {
      const std::size_t start = pos_;
      const std::size_t left = end_ - pos_;
      if (left < 2 + ts_bytes) {
        if (options_.salvage && resyncFrom(start, true)) continue;
        truncated(start, number, left < 2 ? "id" : "timestamp",
                  fmt::format("truncated event: {} bytes left, an event header needs {}", left, 2 + ts_bytes));
        return;
      }
      const auto id = static_cast<std::uint16_t>(readLe(p_ + pos_, 2));
      const int type_or_none = typeOf(id);
      if (type_or_none < 0) {
        if (!options_.salvage) failEvent(start, number, "id", unknownId(id));
        // salvage: a damaged block; resume at the next place where valid events follow
        if (resyncFrom(start)) continue;
        break;
      }
      const std::size_t type = static_cast<std::size_t>(type_or_none);
      const UsdEventType& t = log_.types[type];
      std::uint64_t ts = readLe(p_ + pos_ + 2, ts_bytes);
      if (log_.version == 1) ts *= 1000;  // ms → µs
      pos_ += 2 + ts_bytes;
      if (end_ - pos_ < t.payload_bytes) {
        if (options_.salvage && resyncFrom(start, true)) continue;
        const std::size_t avail = end_ - pos_;
        std::string field = t.name;
        for (const UsdField& f : t.fields) {
          if (f.offset + usdTypeSize(f.type) > avail) {
            field += "." + f.name;
            break;
          }
        }
        truncated(start, number, field,
                  fmt::format("truncated event: its payload needs {} bytes, {} left", t.payload_bytes, avail));
        return;
      }
      UsdEventSeries& s = log_.events[type];
      if (options_.salvage && have_stamp_) {
        // salvage: an event off the log's clock (a zeroed block stamped 0, a damaged stamp) is dropped and counted,
        // never allowed to move the flight's time zero
        const bool back = ts + kMaxStampLag_us < t_latest_us_ || (!s.t_us.empty() && ts < s.t_us.back());
        const bool ahead = ts > t_latest_us_ + kMaxStampLead_us && !chainAt(start, ts);
        if (back || ahead) {
          dropJump(type, ts, back);
          pos_ += t.payload_bytes;
          ++number;
          continue;
        }
      }
      if (!s.t_us.empty() && ts < s.t_us.back()) {
        failEvent(start, number, t.name + ".timestamp",
                  fmt::format("time goes backwards within {}: {} µs after {} µs", t.name, ts, s.t_us.back()));
      }
      t_latest_us_ = have_stamp_ ? std::max(t_latest_us_, ts) : ts;
      have_stamp_ = true;
      last_type_ = static_cast<int>(type);
      if (!s.t_us.empty() && ts == s.t_us.back()) ++duplicates_[type];
      s.t_us.push_back(ts);
      s.offset.push_back(static_cast<std::uint32_t>(start));
      s.number.push_back(static_cast<std::uint32_t>(number));
      s.payload.insert(s.payload.end(), p_ + pos_, p_ + pos_ + t.payload_bytes);
      pos_ += t.payload_bytes;
      ++number;
    }
    finish(number);
  }

  /// Salvage: skips the damaged bytes from `start` to the next valid chain; false when none follows (then the rest
  /// is skipped too, unless keep_tail: then nothing is skipped or counted).
  bool resyncFrom(std::size_t start, bool keep_tail = false) {
    const std::size_t q = resync(start);
    if (q == end_ && keep_tail) return false;  // nothing valid after: the caller reports a truncated tail
    dropLastKept();
    skipped_bytes_ += q - start;
    ++n_resyncs_;
    if (first_skip_.empty()) first_skip_ = fmt::format("the first at byte {}", start);
    pos_ = q;
    return q < end_;
  }

  std::string unknownId(std::uint16_t id) const {
    std::string declared;
    for (std::size_t k = 0; k < ids_.size() && k < 12; ++k) {
      declared += fmt::format("{}{} {}", k == 0 ? "" : ", ", ids_[k].first, log_.types[ids_[k].second].name);
    }
    if (ids_.size() > 12) declared += ", ...";
    return fmt::format("event id {} is not declared in the header (declared: {})", id,
                       declared.empty() ? "none" : declared);
  }

  void truncated(std::size_t start, std::size_t number, const std::string& field, const std::string& what) {
    if (!options_.salvage) failEvent(start, number, field, what);
    report_.notes.push_back(fmt::format("salvage: the last {} bytes (a truncated event {}) are ignored", n_ - start,
                                        number));
    finish(number);
  }

  void finish(std::size_t number) {
    report_.n_events = number;
    report_.skipped_bytes = skipped_bytes_;
    report_.dropped_events = n_jump_dropped_ + n_before_damage_;
    if (skipped_bytes_ > 0)
      report_.warnings.push_back(fmt::format(
          "salvage: {} damaged byte(s) skipped in {} place(s) ({}); reading resumed at the next valid event each time "
          "({} event(s) just before damage dropped too)",
          skipped_bytes_, n_resyncs_, first_skip_, n_before_damage_));
    if (n_jump_dropped_ > 0)
      report_.warnings.push_back(fmt::format(
          "salvage: {} event(s) dropped because their time stamps jump off the log's clock ({}; a zeroed or damaged "
          "block?); {} event(s) just before damage dropped too",
          n_jump_dropped_, first_jump_, n_before_damage_));
    for (std::size_t i = 0; i < duplicates_.size(); ++i) {
      if (duplicates_[i] > 0) {
        report_.notes.push_back(fmt::format("{} events of {} share a timestamp with the previous one", duplicates_[i],
                                            log_.types[i].name));
      }
    }
  }

  const std::uint8_t* p_;
  std::size_t n_;
  const UsdReadOptions& options_;
  UsdReadReport& report_;
  UsdLog log_;
  std::size_t num_types_ = 0;
  std::size_t pos_ = 0;
  std::size_t end_ = 0;
  std::vector<std::pair<std::uint16_t, std::size_t>> ids_;  ///< (id, type index), sorted
  std::vector<std::size_t> duplicates_;
  bool have_stamp_ = false;
  std::uint64_t t_latest_us_ = 0;  ///< the latest stamp kept, over all types
  std::size_t skipped_bytes_ = 0, n_resyncs_ = 0, n_jump_dropped_ = 0, n_before_damage_ = 0;
  int last_type_ = -1;  ///< type of the last event kept (salvage drops it when damage follows it)
  std::string first_skip_, first_jump_;
};

std::size_t headerBytes(const UsdLog& log) {
  std::size_t n = kPreambleBytes;
  for (const UsdEventType& t : log.types) {
    n += 2 + t.name.size() + 1 + 2;
    for (const UsdField& f : t.fields) n += f.name.size() + 4;  // "name(T)\0"
  }
  return n;
}

}  // namespace

std::size_t usdTypeSize(UsdType type) {
  switch (type) {
    case UsdType::kUint8: case UsdType::kInt8: return 1;
    case UsdType::kUint16: case UsdType::kInt16: case UsdType::kHalf: return 2;
    case UsdType::kUint32: case UsdType::kInt32: case UsdType::kFloat: return 4;
  }
  return 0;
}

std::uint32_t crc32(std::string_view bytes) {
  const auto& table = crcTable();
  std::uint32_t c = 0xFFFFFFFFu;
  for (const char ch : bytes) c = table[(c ^ static_cast<std::uint8_t>(ch)) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

int UsdEventType::fieldIndex(std::string_view field) const {
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (fields[i].name == field) return static_cast<int>(i);
  }
  return -1;
}

int UsdLog::typeIndex(std::string_view name) const {
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double UsdLog::value(std::size_t type, std::size_t event, std::size_t field) const {
  const UsdEventType& t = types.at(type);
  const UsdField& f = t.fields.at(field);
  const std::uint8_t* p = events.at(type).payload.data() + event * t.payload_bytes + f.offset;
  const std::uint64_t raw = readLe(p, usdTypeSize(f.type));
  switch (f.type) {
    case UsdType::kUint8: return static_cast<double>(static_cast<std::uint8_t>(raw));
    case UsdType::kInt8: return static_cast<double>(static_cast<std::int8_t>(raw));
    case UsdType::kUint16: return static_cast<double>(static_cast<std::uint16_t>(raw));
    case UsdType::kInt16: return static_cast<double>(static_cast<std::int16_t>(raw));
    case UsdType::kUint32: return static_cast<double>(static_cast<std::uint32_t>(raw));
    case UsdType::kInt32: return static_cast<double>(static_cast<std::int32_t>(raw));
    case UsdType::kFloat: return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
    case UsdType::kHalf: return halfToDouble(static_cast<std::uint16_t>(raw));
  }
  return 0.0;
}

std::string UsdLog::where(std::size_t type, std::size_t event, int field) const {
  const UsdEventType& t = types.at(type);
  const UsdEventSeries& s = events.at(type);
  const std::string name = field < 0 ? t.name : t.name + "." + t.fields.at(static_cast<std::size_t>(field)).name;
  return fmt::format("{}: byte {}, event {} ({})", source, s.offset.at(event), s.number.at(event), name);
}

std::size_t UsdLog::addType(std::uint16_t id, const std::string& name,
                            const std::vector<std::pair<std::string, UsdType>>& fields) {
  if (numEvents() > 0) throw std::invalid_argument("UsdLog::addType: every event type must be added before the events");
  if (name.empty() || name.find('\0') != std::string::npos) {
    throw std::invalid_argument("event-type name must be non-empty and hold no NUL byte");
  }
  if (added_ids_.count(id) != 0) {
    const auto same = std::find_if(types.begin(), types.end(), [&](const UsdEventType& t) { return t.id == id; });
    throw std::invalid_argument(fmt::format("event id {} is declared twice ({} and {})", id,
                                            same != types.end() ? same->name : "?", name));
  }
  if (added_names_.count(name) != 0) throw std::invalid_argument(fmt::format("event type '{}' is declared twice", name));
  UsdEventType t;
  t.id = id;
  t.name = name;
  std::vector<std::string_view> sorted;
  sorted.reserve(fields.size());
  for (const auto& [field, type] : fields) {
    if (field.empty() || field.find_first_of(std::string_view("(\0", 2)) != std::string::npos) {
      throw std::invalid_argument(fmt::format("field name '{}' of {} must be non-empty, without '(' or NUL", field, name));
    }
    t.fields.push_back({field, type, t.payload_bytes});
    t.payload_bytes += usdTypeSize(type);
    sorted.push_back(field);
  }
  std::sort(sorted.begin(), sorted.end());
  if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end()) {
    throw std::invalid_argument(fmt::format("field '{}' of {} is declared twice", *dup, name));
  }
  added_ids_.insert(id);
  added_names_.insert(name);
  types.push_back(std::move(t));
  events.emplace_back();
  return types.size() - 1;
}

std::size_t UsdLog::numEvents() const {
  std::size_t n = 0;
  for (const UsdEventSeries& s : events) n += s.size();
  return n;
}

void UsdLog::addEvent(std::size_t type, std::uint64_t t_us, const std::vector<double>& values) {
  const UsdEventType& t = types.at(type);
  if (values.size() != t.fields.size()) {
    throw std::invalid_argument(fmt::format("{} has {} fields, {} values given", t.name, t.fields.size(), values.size()));
  }
  if (version == 1 && (t_us % 1000 != 0 || t_us / 1000 > std::numeric_limits<std::uint32_t>::max())) {
    throw std::invalid_argument(fmt::format("version 1 holds whole milliseconds below 2^32 ms: {} µs", t_us));
  }
  std::string bytes;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    const UsdType type_i = t.fields[i].type;
    const auto integer = [&](double lo, double hi) {
      if (!(v >= lo && v <= hi) || v != std::floor(v)) {
        throw std::invalid_argument(fmt::format("{}.{} = {} does not fit its type '{}'", t.name, t.fields[i].name, v,
                                                static_cast<char>(type_i)));
      }
      appendLe(bytes, static_cast<std::uint64_t>(static_cast<std::int64_t>(v)), usdTypeSize(type_i));
    };
    switch (type_i) {
      case UsdType::kUint8: integer(0, 255); break;
      case UsdType::kInt8: integer(-128, 127); break;
      case UsdType::kUint16: integer(0, 65535); break;
      case UsdType::kInt16: integer(-32768, 32767); break;
      case UsdType::kUint32: integer(0, 4294967295.0); break;
      case UsdType::kInt32: integer(-2147483648.0, 2147483647.0); break;
      case UsdType::kFloat: appendLe(bytes, std::bit_cast<std::uint32_t>(static_cast<float>(v)), 4); break;
      case UsdType::kHalf: appendLe(bytes, doubleToHalf(v), 2); break;
    }
  }
  if (next_offset_ == 0) {  // first added event: continue after the header and the events already held
    next_offset_ = headerBytes(*this);
    for (std::size_t k = 0; k < types.size(); ++k) {
      next_offset_ += events[k].size() * (2 + timestampBytes(version) + types[k].payload_bytes);
      for (const std::uint32_t m : events[k].number) next_number_ = std::max<std::size_t>(next_number_, m + 1);
    }
  }
  UsdEventSeries& s = events.at(type);
  if (!s.t_us.empty() && t_us < s.t_us.back()) {
    throw std::invalid_argument(fmt::format("{}: time goes backwards ({} µs after {} µs)", t.name, t_us, s.t_us.back()));
  }
  s.t_us.push_back(t_us);
  s.offset.push_back(static_cast<std::uint32_t>(next_offset_));
  s.number.push_back(static_cast<std::uint32_t>(next_number_));
  s.payload.insert(s.payload.end(), bytes.begin(), bytes.end());
  next_offset_ += 2 + timestampBytes(version) + t.payload_bytes;
  ++next_number_;
}

std::string formatUsdLog(const UsdLog& log) {
  if (log.version != 1 && log.version != 2) throw std::invalid_argument(fmt::format("unsupported version {}", log.version));
  std::string out;
  out.push_back(static_cast<char>(kMagic));
  appendLe(out, static_cast<std::uint64_t>(log.version), 2);
  appendLe(out, log.types.size(), 2);
  for (const UsdEventType& t : log.types) {
    appendLe(out, t.id, 2);
    out += t.name;
    out.push_back('\0');
    appendLe(out, t.fields.size(), 2);
    for (const UsdField& f : t.fields) {
      out += f.name;
      out.push_back('(');
      out.push_back(static_cast<char>(f.type));
      out.push_back(')');
      out.push_back('\0');
    }
  }
  // Events in the order of their numbers (the file order of a read log, the call order of a built one).
  std::vector<std::pair<std::uint32_t, std::pair<std::size_t, std::size_t>>> order;
  order.reserve(log.numEvents());
  for (std::size_t k = 0; k < log.events.size(); ++k) {
    for (std::size_t i = 0; i < log.events[k].size(); ++i) order.push_back({log.events[k].number[i], {k, i}});
  }
  std::sort(order.begin(), order.end());
  const std::size_t ts_bytes = timestampBytes(log.version);
  for (const auto& [number, ki] : order) {
    const auto [k, i] = ki;
    const UsdEventType& t = log.types[k];
    const UsdEventSeries& s = log.events[k];
    appendLe(out, t.id, 2);
    appendLe(out, log.version == 1 ? s.t_us[i] / 1000 : s.t_us[i], ts_bytes);
    out.append(reinterpret_cast<const char*>(s.payload.data() + i * t.payload_bytes), t.payload_bytes);
  }
  appendLe(out, crc32(out), kCrcBytes);
  return out;
}

void writeUsdLog(const UsdLog& log, const std::string& path) {
  writeFileAtomically(path, formatUsdLog(log), "event log");
}

UsdLog readUsdLog(const std::string& path, const UsdReadOptions& options, UsdReadReport* report) {
  return parseUsdLog(readTextFile(path, "event log"), path, options, report);
}

UsdLog parseUsdLog(std::string_view bytes, const std::string& source, const UsdReadOptions& options,
                   UsdReadReport* report) {
  UsdReadReport local;
  UsdReadReport& rep = report != nullptr ? *report : local;
  rep = UsdReadReport{};
  return Parser(bytes, source, options, rep).run();
}

}  // namespace uwb
