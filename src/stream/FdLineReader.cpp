/** @file FdLineReader.cpp
 *  @brief Buffered line reading from a file descriptor that stops on a flag.
 */
#include "uwb/stream/FdLineReader.h"

#include <cerrno>
#include <cstring>

#include <poll.h>
#include <unistd.h>

namespace uwb {

namespace {
constexpr int kStopPoll_ms = 100;
}  // namespace

FdLineReader::FdLineReader(int fd, const volatile std::sig_atomic_t* stop, std::function<void()> before_block)
    : fd_(fd), stop_(stop), before_block_(std::move(before_block)) {}

bool FdLineReader::next(std::string& line) {
  while (true) {
    if (stopped()) return false;
    const std::size_t nl = buf_.find('\n', pos_);
    if (nl != std::string::npos) {
      line.assign(buf_, pos_, nl - pos_);
      pos_ = nl + 1;
      ++line_no_;
      return true;
    }
    if (eof_) {
      if (pos_ >= buf_.size()) return false;
      line.assign(buf_, pos_, std::string::npos);  // a last line without '\n'
      pos_ = buf_.size();
      ++line_no_;
      return true;
    }
    buf_.erase(0, pos_);  // keep only the partial line
    pos_ = 0;
    if (before_block_) before_block_();
    // wait in short slices so a stop request that lands just before the read is seen within kStopPoll_ms
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, kStopPoll_ms);
    if (ready == 0 || (ready < 0 && errno == EINTR)) continue;
    char chunk[65536];
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n > 0) {
      buf_.append(chunk, static_cast<std::size_t>(n));
    } else if (n == 0) {
      eof_ = true;
    } else if (errno != EINTR) {
      error_ = std::strerror(errno);
      return false;
    }
  }
}

}  // namespace uwb
