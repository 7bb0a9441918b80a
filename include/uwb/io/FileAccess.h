/** @file FileAccess.h
 *  @brief Reading input files and writing output files safely: inputs must be regular files (or pipes), outputs
 *         appear complete or not at all (written under a temporary name in the same folder, then renamed).
 *
 *  Every file the library and the CLI read or write goes through these functions, so that a directory or a device
 *  given as input is refused with a clear FileError, and a failing command never leaves a half-written output.
 */
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace uwb {

/// Largest input file read into memory [bytes]: 2 GiB − 1 (a file of 2^31 bytes is refused; the largest UTIL flight
/// is ≈ 60 MB).
inline constexpr std::size_t kMaxInputFileBytes = (std::size_t{1} << 31) - 1;

/// Whole file as one string. FileError (naming `what` and the path) when the path does not exist, is a directory,
/// a device or a socket, is larger than kMaxInputFileBytes, or cannot be read. Pipes (e.g. `<(...)`) are accepted.
std::string readTextFile(const std::string& path, const char* what);

/// Writes `text` to `path` atomically: the bytes go to a temporary file `.NAME.tmp-PID-N` in the same folder, which
/// is renamed to `path` only when completely written and flushed. On any failure the temporary file is removed,
/// `path` is left as it was, and FileError names `what` and the path. An existing `path` must be a regular file
/// (a directory, device, FIFO, socket or symbolic link is refused, never replaced) and keeps its permission bits;
/// with protectInputsFromOverwrite() on, a file this process has read (same device and inode) is refused too.
/// Stale temporary files of the same output left by a process that no longer runs are removed first.
void writeFileAtomically(const std::string& path, std::string_view text, const char* what);

/// Checks before any work is done that `path` can be written: its folder exists and accepts a new file; an
/// existing `path` is a regular file (not a directory, device, FIFO, socket or symbolic link) and is none of
/// `inputs` (compared by device and inode, so a hard link or another spelling of an input is caught). FileError
/// naming `what` otherwise. Creates nothing that outlives the call; removes stale temporary files (see above).
void checkOutputFile(const std::string& path, const char* what, const std::vector<std::string>& inputs = {});

/// A fresh temporary name beside `path` in the pattern writeFileAtomically uses (`.NAME.tmp-PID-N` + `suffix`), for
/// outputs written by another program (e.g. a PNG renamed into place); register it with TemporaryFileGuard.
std::string temporaryPathBeside(const std::string& path, const std::string& suffix = "");

/// Removes the temporary files `.NAME.tmp-PID-N*` of the output `path` whose process PID no longer exists (left by
/// a run killed with SIGKILL). Returns how many were removed. Files of running processes are left alone.
std::size_t sweepStaleTemporaryFiles(const std::string& path);

/// Registers a temporary file for removeTemporaryFilesOnSignal() while the guard lives (at most 32 at a time;
/// beyond that the file is only swept by a later run).
class TemporaryFileGuard {
 public:
  explicit TemporaryFileGuard(const std::string& path);
  ~TemporaryFileGuard();
  TemporaryFileGuard(const TemporaryFileGuard&) = delete;
  TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

 private:
  int slot_;
};

/// Unlinks every registered temporary file. Async-signal-safe (lock-free atomics and unlink(2) only): for a
/// SIGINT/SIGTERM handler, which then re-raises the signal.
void removeTemporaryFilesOnSignal() noexcept;

/// From now on every file readTextFile() reads is remembered (device, inode), and writeFileAtomically() refuses to
/// replace one of them. The CLI turns it on; the library alone leaves it off (a program may rewrite what it read).
void protectInputsFromOverwrite();

/// Checks before any work is done that the output folder `dir` exists and is writable, or can be created (its
/// nearest existing parent is a writable folder). FileError naming `what` otherwise. Creates nothing.
void checkOutputDirectory(const std::string& dir, const char* what);

}  // namespace uwb
