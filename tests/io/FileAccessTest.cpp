/** @file FileAccessTest.cpp
 *  @brief Inputs must be files (directories and devices refused with a clear FileError, not std::bad_alloc);
 *         outputs appear complete or not at all, and unwritable outputs are found before any work.
 */
#include "uwb/io/FileAccess.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using ::testing::HasSubstr;

/// Names in `dir` (temporary files included).
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(FileAccess, ReadsAWholeFile) {
  TempDir dir;
  const std::string text = "a,b\n1,2\n" + std::string(200000, 'x');
  EXPECT_EQ(readTextFile(dir.write("f.txt", text), "test file"), text);
}

TEST(FileAccess, ADirectoryAsInputIsAClearFileErrorForEveryReader) {
  // GIVEN a directory where a flight, a survey or a trajectory is expected (used to end in std::bad_alloc)
  TempDir dir;
  const std::string d = dir.file("");
  // THEN each reader refuses it, naming the path and saying what it is
  test::expectThrows<FileError>([&] { (void)readFlightCsv(d); }, {"flight file", "is a directory"});
  test::expectThrows<FileError>([&] { (void)readAnchorSurvey(d); }, {"anchor survey", "is a directory"});
  test::expectThrows<FileError>([&] { (void)readTrajectoryCsv(d); }, {"trajectory file", "is a directory"});
}

TEST(FileAccess, ADeviceAsInputIsRefused) {
  if (!fs::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
  test::expectThrows<FileError>([] { (void)readFlightCsv("/dev/zero"); }, {"/dev/zero", "character device"});
}

TEST(FileAccess, AMissingInputNamesThePath) {
  TempDir dir;
  test::expectThrows<FileError>([&] { (void)readTextFile(dir.file("none.csv"), "flight file"); }, {"none.csv", "cannot open"});
}

TEST(FileAccess, AtomicWriteReplacesTheFileAndLeavesNoTemporary) {
  TempDir dir;
  const std::string path = dir.write("out.csv", "old contents\n");
  writeFileAtomically(path, "new\n", "test output");
  EXPECT_EQ(readTextFile(path, "test output"), "new\n");
  EXPECT_EQ(listing(dir.file("")), std::vector<std::string>{"out.csv"});
}

TEST(FileAccess, AFailedWriteLeavesNeitherTheFileNorATemporary) {
  // GIVEN an output whose folder does not exist, and one that is a directory
  TempDir dir;
  fs::create_directories(dir.file("sub"));
  // WHEN writing fails
  test::expectThrows<FileError>([&] { writeFileAtomically(dir.file("missing/out.csv"), "x", "test output"); },
                  {"missing/out.csv", "test output"});
  test::expectThrows<FileError>([&] { writeFileAtomically(dir.file("sub"), "x", "test output"); }, {"is a directory"});
  // THEN nothing was created
  EXPECT_EQ(listing(dir.file("")), std::vector<std::string>{"sub"});
  EXPECT_TRUE(fs::is_empty(dir.file("sub")));
}

TEST(FileAccess, AWriteThatFailsHalfwayLeavesTheOldFileAndNoTemporary) {
  // GIVEN an existing output and a file-size limit of 4 kB (the write fails with EFBIG after 4 kB, as on a full disk)
  TempDir dir;
  const std::string path = dir.write("out.csv", "old contents\n");
  struct rlimit old_limit {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old_limit;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  // WHEN 100 kB are written
  bool failed = false;
  try {
    writeFileAtomically(path, std::string(100000, 'x'), "test output");
  } catch (const FileError& e) {
    failed = true;
    EXPECT_THAT(e.what(), HasSubstr("out.csv"));
  }
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  // THEN it is a FileError, the old file is intact and no partial or temporary file is left
  EXPECT_TRUE(failed);
  EXPECT_EQ(readTextFile(path, "test output"), "old contents\n");
  EXPECT_EQ(listing(dir.file("")), std::vector<std::string>{"out.csv"});
}

TEST(FileAccess, CheckOutputFileFindsProblemsBeforeTheWorkAndCreatesNothing) {
  TempDir dir;
  fs::create_directories(dir.file("sub"));
  checkOutputFile(dir.file("ok.csv"), "test output");  // fine: no exception
  test::expectThrows<FileError>([&] { checkOutputFile(dir.file("nofolder/x.csv"), "trajectory file"); },
                  {"trajectory file", "does not exist"});
  test::expectThrows<FileError>([&] { checkOutputFile(dir.file("sub"), "trajectory file"); }, {"is a directory"});
  test::expectThrows<FileError>([&] { checkOutputFile("", "trajectory file"); }, {"empty"});
  EXPECT_EQ(listing(dir.file("")), std::vector<std::string>{"sub"});
}

TEST(FileAccess, CheckOutputDirectoryAcceptsAFolderToBeCreated) {
  TempDir dir;
  checkOutputDirectory(dir.file("a/b/c"), "report folder");  // parents will be created
  EXPECT_FALSE(fs::exists(dir.file("a")));
  const std::string file = dir.write("plain", "x");
  test::expectThrows<FileError>([&] { checkOutputDirectory(file + "/report", "report folder"); }, {"is not a folder"});
}

}  // namespace
}  // namespace uwb
