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

namespace uwb {

/// Largest input file read into memory [bytes] (the largest UTIL flight is ≈ 60 MB).
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{1} << 31;

/// Whole file as one string. FileError (naming `what` and the path) when the path does not exist, is a directory,
/// a device or a socket, is larger than kMaxInputFileBytes, or cannot be read. Pipes (e.g. `<(...)`) are accepted.
std::string readTextFile(const std::string& path, const char* what);

/// Writes `text` to `path` atomically: the bytes go to a temporary file in the same folder, which is renamed to
/// `path` only when completely written and flushed. On any failure the temporary file is removed, `path` is left
/// as it was, and FileError names `what` and the path.
void writeFileAtomically(const std::string& path, std::string_view text, const char* what);

/// Checks before any work is done that `path` can be written: its folder exists and accepts a new file, and
/// `path` is not a directory. FileError naming `what` otherwise. Creates nothing that outlives the call.
void checkOutputFile(const std::string& path, const char* what);

/// Checks before any work is done that the output folder `dir` exists and is writable, or can be created (its
/// nearest existing parent is a writable folder). FileError naming `what` otherwise. Creates nothing.
void checkOutputDirectory(const std::string& dir, const char* what);

}  // namespace uwb
