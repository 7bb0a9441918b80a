/** @file FileAccess.cpp */
#include "uwb/io/FileAccess.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

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

/// A name in the folder of `path` that does not exist yet (the caller opens it with O_EXCL and retries).
std::string temporaryName(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  return (folderOf(path) / fmt::format(".{}.tmp-{}-{}", p.filename().string(), ::getpid(), counter++)).string();
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
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw FileError(fmt::format("cannot write {} '{}': it is a directory", what, path));
  }
  std::string tmp;
  Fd f;
  for (int attempt = 0; attempt < 100 && f.fd < 0; ++attempt) {
    tmp = temporaryName(path);
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // permissions: 0666 & ~umask
    if (f.fd < 0 && errno != EEXIST) break;
  }
  if (f.fd < 0) throw FileError(fmt::format("cannot create {} '{}': {}", what, path, std::strerror(errno)));
  const auto fail = [&](const char* step) {
    const int err = errno;
    ::close(f.fd);
    f.fd = -1;
    ::unlink(tmp.c_str());
    throw FileError(fmt::format("cannot {} {} '{}': {}", step, what, path, std::strerror(err)));
  };
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
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(err)));
  }
}

void checkOutputFile(const std::string& path, const char* what) {
  if (path.empty()) throw FileError(fmt::format("{}: empty output file name", what));
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw FileError(fmt::format("cannot write {} '{}': it is a directory", what, path));
  }
  const fs::path folder = folderOf(path);
  if (::stat(folder.c_str(), &st) != 0) {
    throw FileError(fmt::format("cannot write {} '{}': folder '{}' does not exist", what, path, folder.string()));
  }
  if (!S_ISDIR(st.st_mode)) {
    throw FileError(fmt::format("cannot write {} '{}': '{}' is not a folder", what, path, folder.string()));
  }
  // The real test: create (and remove) a file of the kind writeFileAtomically creates.
  const std::string tmp = temporaryName(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw FileError(fmt::format("cannot write {} '{}': {}", what, path, std::strerror(errno)));
  ::close(fd);
  ::unlink(tmp.c_str());
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
