/** @file OutputTargetTest.cpp
 *  @brief What an output may replace (regular files only, never an input, keeping their mode), temporary files
 *         removed on a signal and swept after a SIGKILL, the input size limit and the JSON nesting cap.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/JsonFile.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using ::testing::HasSubstr;

/// Runs `f` in a child process (so that process-wide state it sets does not leak into other tests); its exit code.
template <class F>
int inChild(F&& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int code = 1;
    try {
      code = f();
    } catch (...) {
      code = 2;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + WTERMSIG(status);
}

TEST(OutputTarget, ANonRegularTargetIsRefusedAndLeftAsItIs) {
  TempDir dir;
  const std::string fifo = dir.file("p.fifo"), link = dir.file("link.csv"), target = dir.write("target.csv", "keep");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_symlink(target, link);
  test::expectThrows<FileError>([&] { writeFileAtomically(fifo, "x", "trajectory"); }, {"FIFO"});
  test::expectThrows<FileError>([&] { checkOutputFile(fifo, "trajectory"); }, {"FIFO"});
  test::expectThrows<FileError>([&] { writeFileAtomically(link, "x", "trajectory"); }, {"symbolic link"});
  test::expectThrows<FileError>([&] { checkOutputFile(link, "trajectory"); }, {"symbolic link"});
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readTextFile(target, "t"), "keep");
  if (fs::exists("/dev/null")) {
    test::expectThrows<FileError>([] { writeFileAtomically("/dev/null", "x", "trajectory"); }, {"character device"});
  }
}

TEST(OutputTarget, AReplacedFileKeepsItsPermissionBits) {
  TempDir dir;
  const std::string path = dir.write("secret.csv", "old");
  ASSERT_EQ(::chmod(path.c_str(), 0600), 0);
  writeFileAtomically(path, "new", "test file");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  EXPECT_EQ(readTextFile(path, "t"), "new");
}

TEST(OutputTarget, CheckOutputFileRefusesAnInputUnderAnyName) {
  TempDir dir;
  const std::string input = dir.write("flight.csv", "data"), hard = dir.file("other.csv");
  fs::create_hard_link(input, hard);
  test::expectThrows<FileError>([&] { checkOutputFile(input, "trajectory", {input}); }, {"input file"});
  test::expectThrows<FileError>([&] { checkOutputFile(hard, "trajectory", {"", input}); }, {"input file"});
  EXPECT_NO_THROW(checkOutputFile(dir.file("new.csv"), "trajectory", {input}));
}

TEST(OutputTarget, WithTheGuardOnAFileReadIsNeverReplaced) {
  TempDir dir;
  const std::string input = dir.write("flight.csv", "data");
  const int code = inChild([&] {
    protectInputsFromOverwrite();
    readTextFile(input, "flight");
    try {
      writeFileAtomically(input, "destroyed", "trajectory");
    } catch (const FileError& e) {
      return std::string(e.what()).find("input files") != std::string::npos ? 0 : 3;
    }
    return 4;
  });
  EXPECT_EQ(code, 0);
  EXPECT_EQ(readTextFile(input, "t"), "data");
}

TEST(OutputTarget, ASignalRemovesTheRegisteredTemporaryFiles) {
  TempDir dir;
  const std::string tmp = dir.write(".out.csv.tmp-1-0", "partial");
  const int code = inChild([&] {
    struct sigaction sa {};
    sa.sa_handler = [](int) {
      removeTemporaryFilesOnSignal();
      ::_exit(0);
    };
    sigaction(SIGTERM, &sa, nullptr);
    const TemporaryFileGuard guard(tmp);
    ::raise(SIGTERM);
    return 5;
  });
  EXPECT_EQ(code, 0);
  EXPECT_FALSE(fs::exists(tmp));
}

TEST(OutputTarget, TheSweepRemovesOnlyTheFilesOfDeadProcesses) {
  TempDir dir;
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const std::string out = dir.file("t.csv");
  const std::string d = std::to_string(dead);
  const std::vector<std::string> gone{".t.csv.tmp-" + d + "-0", ".t.csv.tmp-" + d + "-17.png"};
  const std::vector<std::string> kept{".t.csv.tmp-" + std::to_string(::getppid()) + "-0",  // a live process
                                      ".t.csv.tmp-" + d, ".t.csv.tmp-x-1", ".u.csv.tmp-" + d + "-0", "t.csv"};
  for (const auto& n : gone) dir.write(n, "x");
  for (const auto& n : kept) dir.write(n, "x");
  EXPECT_EQ(sweepStaleTemporaryFiles(out), gone.size());
  for (const auto& n : gone) EXPECT_FALSE(fs::exists(dir.file(n))) << n;
  for (const auto& n : kept) EXPECT_TRUE(fs::exists(dir.file(n))) << n;
}

TEST(OutputTarget, AFileOfExactlyTwoGibibytesIsRefused) {
  TempDir dir;
  const std::string path = dir.file("big.csv");
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, off_t{1} << 31), 0);  // sparse: no disk space used
  ::close(fd);
  test::expectThrows<FileError>([&] { readTextFile(path, "flight file"); }, {"too large (2147483648 bytes"});
}

TEST(JsonNesting, TheCapCountsBracketsOutsideStringsOnly) {
  const std::string ok = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
  EXPECT_EQ(jsonNestingTooDeepAt(ok), std::string_view::npos);
  EXPECT_EQ(jsonNestingTooDeepAt("[" + ok + "]"), static_cast<std::size_t>(kMaxJsonDepth));
  EXPECT_EQ(jsonNestingTooDeepAt("{\"k\": \"" + std::string(200, '[') + "\\\"[\"}"), std::string_view::npos);
  try {
    parseJsonText("{\"a\":\n " + std::string(100000, '['), "cfg.json", "config file");
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cfg.json:2:65"));
    EXPECT_THAT(e.what(), HasSubstr("nested deeper than 64"));
  }
}

}  // namespace
}  // namespace uwb
