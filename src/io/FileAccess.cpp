/** @file FileAccess.cpp */
#include "uwb/io/FileAccess.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <utility>
#include <vector>

#include "uwb/core/Error.h"

namespace uwb {

namespace {

namespace fs = std::filesystem;

/// Closes a POSIX file descriptor at scope exit.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// The folder that holds `path` ("." for a bare file name).
fs::path folderOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// ------------------------------------------------------------------------------------ files read by this process

/// Device and inode of every file read while the guard is on (protectInputsFromOverwrite).
struct InputRegistry {
  std::mutex mutex;
  bool on = false;
  std::vector<std::pair<dev_t, ino_t>> files;
};
InputRegistry& inputRegistry() {
  static InputRegistry r;
  return r;
}

void rememberInput(const struct stat& st) {
  InputRegistry& r = inputRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (r.on) r.files.emplace_back(st.st_dev, st.st_ino);
}

bool wasReadAsInput(const struct stat& st) {
  InputRegistry& r = inputRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& [dev, ino] : r.files)
    if (dev == st.st_dev && ino == st.st_ino) return true;
  return false;
}

// ------------------------------------------------------------------------------ temporary files, signal-safe list

/// Temporary files being written, for removeTemporaryFilesOnSignal(). A fixed table of fixed-size slots: the
/// signal handler only reads lock-free atomics and calls unlink(2), both async-signal-safe.
constexpr int kTempSlots = 32;
constexpr std::size_t kTempPathBytes = 4096;
struct TempSlot {
  std::atomic<int> state{0};  ///< 0 free, 1 being filled, 2 holds a path to remove on a signal
  char path[kTempPathBytes]{};
};
TempSlot g_temp_slots[kTempSlots];
static_assert(std::atomic<int>::is_always_lock_free);

/// Registers `path`; -1 when the table is full or the path too long (the file is then only swept at a later run).
int registerTemporary(const std::string& path) {
  if (path.size() >= kTempPathBytes) return -1;
  for (int i = 0; i < kTempSlots; ++i) {
    int expected = 0;
    if (g_temp_slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(g_temp_slots[i].path, path.c_str(), path.size() + 1);
      g_temp_slots[i].state.store(2);
      return i;
    }
  }
  return -1;
}

void unregisterTemporary(int slot) {
  if (slot >= 0) g_temp_slots[slot].state.store(0);
}

/// "<folder>/.<name>.tmp-<pid>-<n><suffix>": the pattern sweepStaleTemporaryFiles() recognises.
std::string temporaryName(const std::string& path, const std::string& suffix = "") {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  return (folderOf(path) / fmt::format(".{}.tmp-{}-{}{}", p.filename().string(), ::getpid(), counter++, suffix))
      .string();
}

/// The pid of a temporary file name made by temporaryName() for the output `name` (0 when `entry` is not one).
pid_t temporaryOwner(const std::string& entry, const std::string& name) {
  const std::string prefix = "." + name + ".tmp-";
  if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) return 0;
  std::size_t i = prefix.size();
  long long pid = 0;
  const std::size_t pid_begin = i;
  while (i < entry.size() && entry[i] >= '0' && entry[i] <= '9' && i - pid_begin < 10) pid = pid * 10 + (entry[i++] - '0');
  if (i == pid_begin || i >= entry.size() || entry[i] != '-') return 0;
  const std::size_t n_begin = ++i;
  while (i < entry.size() && entry[i] >= '0' && entry[i] <= '9') ++i;
  if (i == n_begin || (i < entry.size() && entry[i] != '.')) return 0;
  return pid > 0 && pid <= 0x7fffffff ? static_cast<pid_t>(pid) : 0;
}

/// Refuses an existing output target that is not a regular file, or that is one of the run's inputs.
void checkTarget(const std::string& path, const char* what, const char* verb) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return;  // absent: will be created
  if (!S_ISREG(st.st_mode)) {
    const char* hint = S_ISLNK(st.st_mode) ? " (outputs are not written through links: give the link's target)" : "";
    throw FileError(fmt::format("cannot {} {} '{}': it is {}, not a regular file{}", verb, what, path,
                                kindOf(st.st_mode), hint));
  }
  if (wasReadAsInput(st)) {
    throw FileError(fmt::format("cannot {} {} '{}': it is one of this run's input files (it would be destroyed)",
                                verb, what, path));
  }
}

}  // namespace

std::string readTextFile(const std::string& path, const char* what) {
  Fd f;
  f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f.fd < 0) throw FileError(fmt::format("cannot open {} '{}': {}", what, path, std::strerror(errno)));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw FileError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) {
    throw FileError(fmt::format("cannot read {} '{}': it is {}, expected a file", what, path, kindOf(st.st_mode)));
  }
  rememberInput(st);
  if (S_ISREG(st.st_mode) && static_cast<std::size_t>(st.st_size) > kMaxInputFileBytes) {
    throw FileError(fmt::format("{} '{}' is too large ({} bytes; at most {})", what, path, st.st_size,
                                kMaxInputFileBytes));
  }
  std::string text;
  if (S_ISREG(st.st_mode)) text.reserve(static_cast<std::size_t>(st.st_size));
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw FileError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
    }
    if (text.size() + static_cast<std::size_t>(n) > kMaxInputFileBytes) {
      throw FileError(fmt::format("{} '{}' is too large (more than {} bytes)", what, path, kMaxInputFileBytes));
    }
    text.append(buf, static_cast<std::size_t>(n));
  }
  return text;
}

void writeFileAtomically(const std::string& path, std::string_view text, const char* what) {
  checkTarget(path, what, "write");
  struct stat st {};
  const bool replaces = ::stat(path.c_str(), &st) == 0;
  const mode_t old_mode = st.st_mode & 07777;
  sweepStaleTemporaryFiles(path);
  std::string tmp;
  Fd f;
  for (int attempt = 0; attempt < 100 && f.fd < 0; ++attempt) {
    tmp = temporaryName(path);
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // permissions: 0666 & ~umask
    if (f.fd < 0 && errno != EEXIST) break;
  }
  if (f.fd < 0) throw FileError(fmt::format("cannot create {} '{}': {}", what, path, std::strerror(errno)));
  const TemporaryFileGuard guard(tmp);  // removed by a SIGINT/SIGTERM handler (removeTemporaryFilesOnSignal)
  const auto fail = [&](const char* step) {
    const int err = errno;
    ::close(f.fd);
    f.fd = -1;
    ::unlink(tmp.c_str());
    throw FileError(fmt::format("cannot {} {} '{}': {}", step, what, path, std::strerror(err)));
  };
  // A replaced file keeps its permission bits (a 0600 file stays 0600).
  if (replaces && ::fchmod(f.fd, old_mode) != 0) fail("write");
  for (std::size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(f.fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(f.fd) != 0 && errno != EINVAL && errno != EROFS) fail("write");
  const int fd = f.fd;
  f.fd = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(err)));
  }
  // Checked once more just before the rename: the target may have been replaced while the run worked.
  try {
    checkTarget(path, what, "write");
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(err)));
  }
}

void checkOutputFile(const std::string& path, const char* what, const std::vector<std::string>& inputs) {
  if (path.empty()) throw FileError(fmt::format("{}: empty output file name", what));
  checkTarget(path, what, "write");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    for (const std::string& input : inputs) {
      struct stat in {};
      if (!input.empty() && ::stat(input.c_str(), &in) == 0 && in.st_dev == st.st_dev && in.st_ino == st.st_ino) {
        throw FileError(fmt::format("cannot write {} '{}': it is the input file '{}' (it would be destroyed)", what,
                                    path, input));
      }
    }
  }
  const fs::path folder = folderOf(path);
  if (::stat(folder.c_str(), &st) != 0) {
    throw FileError(fmt::format("cannot write {} '{}': folder '{}' does not exist", what, path, folder.string()));
  }
  if (!S_ISDIR(st.st_mode)) {
    throw FileError(fmt::format("cannot write {} '{}': '{}' is not a folder", what, path, folder.string()));
  }
  sweepStaleTemporaryFiles(path);
  // The real test: create (and remove) a file of the kind writeFileAtomically creates.
  const std::string tmp = temporaryName(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(errno)));
  ::close(fd);
  ::unlink(tmp.c_str());
}

std::string temporaryPathBeside(const std::string& path, const std::string& suffix) {
  return temporaryName(path, suffix);
}

std::size_t sweepStaleTemporaryFiles(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  if (name.empty()) return 0;
  const fs::path folder = folderOf(path);
  DIR* d = ::opendir(folder.c_str());
  if (d == nullptr) return 0;
  std::size_t removed = 0;
  while (const dirent* e = ::readdir(d)) {
    const pid_t pid = temporaryOwner(e->d_name, name);
    if (pid == 0 || pid == ::getpid()) continue;
    // Only the files of a process that no longer exists (a run killed by SIGKILL or a power cut).
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;
    const fs::path stale = folder / e->d_name;
    struct stat st {};
    if (::lstat(stale.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::unlink(stale.c_str()) == 0) ++removed;
  }
  ::closedir(d);
  return removed;
}

TemporaryFileGuard::TemporaryFileGuard(const std::string& path) : slot_(registerTemporary(path)) {}
TemporaryFileGuard::~TemporaryFileGuard() { unregisterTemporary(slot_); }

void removeTemporaryFilesOnSignal() noexcept {
  for (TempSlot& slot : g_temp_slots) {
    if (slot.state.load() == 2) ::unlink(slot.path);
  }
}

void protectInputsFromOverwrite() {
  InputRegistry& r = inputRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.on = true;
}

void checkOutputDirectory(const std::string& dir, const char* what) {
  if (dir.empty()) throw FileError(fmt::format("{}: empty output folder name", what));
  fs::path p(dir);
  struct stat st {};
  // Walk up to the nearest existing path: it must be a folder we can create entries in.
  while (::stat(p.c_str(), &st) != 0) {
    if (errno != ENOENT && errno != ENOTDIR) throw FileError(fmt::format("cannot create {} '{}': {}", what, dir, std::strerror(errno)));
    const fs::path parent = p.parent_path();
    p = parent.empty() || parent == p ? fs::path(".") : parent;
  }
  if (!S_ISDIR(st.st_mode)) {
    throw FileError(fmt::format("cannot create {} '{}': '{}' is not a folder", what, dir, p.string()));
  }
  if (::access(p.c_str(), W_OK | X_OK) != 0) {
    throw FileError(fmt::format("cannot write {} '{}': '{}': {}", what, dir, p.string(), std::strerror(errno)));
  }
}

}  // namespace uwb
