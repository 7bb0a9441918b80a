/** @file UsdLog.h
 *  @brief The Crazyflie uSD-card deck's binary event log (`cfusdlog`, format versions 1 and 2): read, build, write.
 *
 *  Layout (little-endian; docs/io.md §6): magic byte 0xBC; uint16 version; uint16 number of event types; per event
 *  type: uint16 id, NUL-terminated name, uint16 number of fields, per field a NUL-terminated "name(T)" with T a
 *  Python struct type character (B b H h I i f e); then the events: uint16 id, timestamp (version 1: uint32 ms,
 *  version 2: uint64 µs), payload (the fields packed, no padding); last, a CRC-32 (zlib's) of every byte before it.
 *
 *  The reader keeps each event type's payloads packed as they were in the file, so its memory is about the file's
 *  size whatever the ids; ids are looked up in a sorted list (no table sized by an id). Every error is an
 *  InputError "file: byte B, event K (type.field): ..." (K counts events from 0; header errors name the byte only).
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace uwb {

/// Field types: the Python struct characters the firmware writes (uint8 … float, 'e' = IEEE half).
enum class UsdType : char {
  kUint8 = 'B',
  kInt8 = 'b',
  kUint16 = 'H',
  kInt16 = 'h',
  kUint32 = 'I',
  kInt32 = 'i',
  kFloat = 'f',
  kHalf = 'e',
};
/// Bytes of one value of `type`.
std::size_t usdTypeSize(UsdType type);

struct UsdField {
  std::string name;  ///< e.g. "distanceDiff" (event payload) or "acc.x" (a log variable added to the event)
  UsdType type = UsdType::kFloat;
  std::size_t offset = 0;  ///< byte offset within the payload
};

struct UsdEventType {
  std::uint16_t id = 0;
  std::string name;  ///< e.g. "estTDOA"
  std::vector<UsdField> fields;
  std::size_t payload_bytes = 0;  ///< sum of the field sizes
  /// Index of the field called `field`, or -1.
  int fieldIndex(std::string_view field) const;
};

/// All events of one type in file order. Payloads stay packed as in the file.
struct UsdEventSeries {
  std::vector<std::uint64_t> t_us;     ///< timestamp [µs] (version 1: ms × 1000)
  std::vector<std::uint32_t> offset;   ///< byte offset of the event in the file (for messages)
  std::vector<std::uint32_t> number;   ///< 0-based event number in the file (for messages)
  std::vector<std::uint8_t> payload;   ///< size() × payload_bytes bytes
  std::size_t size() const { return t_us.size(); }
};

/// A whole log: the event types of the header and, parallel to them, their events.
struct UsdLog {
  std::string source;  ///< file name, for messages
  int version = 2;     ///< 1: uint32 ms timestamps, 2: uint64 µs timestamps
  std::vector<UsdEventType> types;
  std::vector<UsdEventSeries> events;  ///< events[i] holds the events of types[i]

  /// Index of the event type called `name`, or -1.
  int typeIndex(std::string_view name) const;
  /// Field `field` of event `event` of type `type`, as a double (exact for every field type).
  double value(std::size_t type, std::size_t event, std::size_t field) const;
  /// "file: byte B, event K (type.field)" for messages about one value (field < 0: the event as a whole).
  std::string where(std::size_t type, std::size_t event, int field = -1) const;

  // ---- building a log in code (tests, export) ----
  /// Appends an event type; std::invalid_argument on an id or name already added, an empty name, a field name that
  /// is empty or repeated or holds '(' or NUL. The checks take O(1) per type and O(F log F) per type of F fields.
  std::size_t addType(std::uint16_t id, const std::string& name, const std::vector<std::pair<std::string, UsdType>>& fields);
  /// Appends one event of type index `type` (values converted to the field types, rounding floats to float32
  /// and half; std::invalid_argument when a value does not fit its integer type or the count is wrong). Events
  /// are numbered, and written by formatUsdLog, in the order of the calls.
  void addEvent(std::size_t type, std::uint64_t t_us, const std::vector<double>& values);
  std::size_t numEvents() const;

 private:
  std::size_t next_offset_ = 0;  ///< file offset of the next added event (0: not yet known)
  std::size_t next_number_ = 0;  ///< number of the next added event
  std::unordered_set<std::uint16_t> added_ids_;  ///< ids and names given to addType (its duplicate check)
  std::unordered_set<std::string> added_names_;
};

struct UsdReadOptions {
  /// Salvage a log whose writing was cut (the deck lost power) or damaged: a CRC mismatch and a truncated last event
  /// become notes instead of errors, and the events are read up to the last complete one. A damaged block (an
  /// undeclared id, an event cut short) is skipped up to the next place where valid events follow (declared ids,
  /// whole payloads, stamps on the log's clock), and reading resumes there; an event whose stamp jumps off the log's
  /// clock (more than 1 s behind the latest stamp, as a zeroed block's stamps of 0 do, or more than 10 s ahead of it
  /// with no events after it to confirm the jump) is dropped. Both are counted and reported as warnings.
  bool salvage = false;
};

struct UsdReadReport {
  std::size_t n_bytes = 0;
  std::size_t n_events = 0;
  bool crc_ok = false;
  std::vector<std::string> notes;  ///< e.g. "12 events of estTDOA share a timestamp with the previous one"
  std::size_t skipped_bytes = 0;   ///< salvage: damaged bytes skipped
  std::size_t dropped_events = 0;  ///< salvage: events dropped (stamps that jump, the event just before damage)
  std::vector<std::string> warnings;  ///< salvage: what was skipped or dropped (a user must see these)
};

/// Reads a cfusdlog file. FileError when it cannot be read; InputError (located as in the file comment) on a bad
/// magic byte, an unsupported version, a malformed header (unterminated name, unknown field type, duplicate id or
/// name), an event with an id the header does not declare, a truncated event, a timestamp that decreases within an
/// event type, or a CRC mismatch (unless options.salvage).
UsdLog readUsdLog(const std::string& path, const UsdReadOptions& options = {}, UsdReadReport* report = nullptr);
/// Same on bytes already in memory; `source` names them in messages.
UsdLog parseUsdLog(std::string_view bytes, const std::string& source, const UsdReadOptions& options = {},
                   UsdReadReport* report = nullptr);

/// The file bytes of a log built with addType/addEvent (events in the order they were added), CRC included.
/// A log that was read (not built) is written type by type. parseUsdLog(formatUsdLog(log)) reproduces it.
std::string formatUsdLog(const UsdLog& log);
/// Writes formatUsdLog(log) atomically (io/FileAccess.h).
void writeUsdLog(const UsdLog& log, const std::string& path);

/// CRC-32 of the cfusdlog trailer (IEEE 802.3 polynomial, reflected, as zlib's crc32).
std::uint32_t crc32(std::string_view bytes);

}  // namespace uwb
