/** @file FdLineReaderTest.cpp
 *  @brief Lines from a pipe: split across reads, a last line without newline, and the stop flag.
 */
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <unistd.h>

#include "uwb/stream/FdLineReader.h"

namespace uwb {
namespace {

TEST(FdLineReader, ReadsEveryLineIncludingALastOneWithoutNewline) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string text = "a,1\n\nb,2\nc,3";
  ASSERT_EQ(::write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fds[1]);
  int n_blocks = 0;
  FdLineReader reader(fds[0], nullptr, [&n_blocks] { ++n_blocks; });
  std::vector<std::string> lines;
  for (std::string l; reader.next(l);) lines.push_back(l);
  ::close(fds[0]);
  EXPECT_EQ(lines, (std::vector<std::string>{"a,1", "", "b,2", "c,3"}));
  EXPECT_EQ(reader.lineNumber(), 4u);
  EXPECT_GE(n_blocks, 1);  // flushed before waiting
  EXPECT_TRUE(reader.error().empty());
}

TEST(FdLineReader, StopsWhenTheFlagIsSet) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string text = "x\ny\n";
  ASSERT_EQ(::write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  volatile std::sig_atomic_t stop = 0;
  FdLineReader reader(fds[0], &stop);
  std::string l;
  ASSERT_TRUE(reader.next(l));
  EXPECT_EQ(l, "x");
  stop = 1;  // the write end stays open: without the flag the next read would block after "y"
  EXPECT_FALSE(reader.next(l));
  EXPECT_TRUE(reader.stopped());
  ::close(fds[0]);
  ::close(fds[1]);
}

}  // namespace
}  // namespace uwb
