/** @file FdLineReader.h
 *  @brief Lines from a file descriptor (stdin of `uwbtdoa stream`) that give up when asked to stop: a signal
 *         handler sets the stop flag, which is checked at least every 100 ms while waiting for input, so
 *         SIGINT/SIGTERM end the loop cleanly.
 */
#pragma once

#include <csignal>
#include <functional>
#include <string>

namespace uwb {

class FdLineReader {
 public:
  /// `stop`: checked before and after every blocking read (may be null). `before_block`: called before a read()
  /// that may block (e.g. to flush the output), may be empty.
  FdLineReader(int fd, const volatile std::sig_atomic_t* stop, std::function<void()> before_block = {});

  /// The next line without its '\n' (a last line without one is returned too). False at end of input, when asked
  /// to stop, or on a read error (error() then tells).
  bool next(std::string& line);
  std::size_t lineNumber() const { return line_no_; }
  bool stopped() const { return stop_ != nullptr && *stop_ != 0; }
  const std::string& error() const { return error_; }

 private:
  int fd_;
  const volatile std::sig_atomic_t* stop_;
  std::function<void()> before_block_;
  std::string buf_;
  std::size_t pos_ = 0;
  bool eof_ = false;
  std::size_t line_no_ = 0;
  std::string error_;
};

}  // namespace uwb
