// Result folders as transactions (lib/io/result_folder.hpp, docs/guide/result-folders.md).
#include "lib/io/history_writer.hpp"
#include "lib/io/result_folder.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace shelldyn;

namespace {
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("shelldyn-result-folder-" + name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

// Another process holds the folder: refused with one line naming it; released: the file is gone.
TEST(ResultFolder, LockIsExclusiveAcrossProcessesAndRemovedOnRelease) {
  const fs::path d = scratch("lock");
  int ready[2], go[2];
  ASSERT_EQ(pipe(ready), 0);
  ASSERT_EQ(pipe(go), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    {
      FolderLock held(d.string(), StaleLock::refuse, nullptr);
      char c = 1;
      if (write(ready[1], &c, 1) != 1) _exit(2);
      if (read(go[0], &c, 1) != 1) _exit(3);
    }
    _exit(0);
  }
  char c = 0;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  try {
    FolderLock second(d.string(), StaleLock::take_over, nullptr);
    ADD_FAILURE() << "a second process took a held folder";
  } catch (const FolderBusy& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("in use by pid " + std::to_string(child)), std::string::npos) << w;
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  }
  ASSERT_EQ(write(go[1], &c, 1), 1);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_FALSE(fs::exists(d / lock_file_name()));
  FolderLock again(d.string(), StaleLock::refuse, nullptr);  // free again, no stale record
  EXPECT_TRUE(again.held());
}

// A process killed while holding the folder leaves a stale lock: refused or taken over with a note.
TEST(ResultFolder, StaleLockOfAKilledProcessIsReported) {
  const fs::path d = scratch("stale");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    FolderLock held(d.string(), StaleLock::refuse, nullptr);
    _exit(0);  // no destructor: as if killed
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(fs::exists(d / lock_file_name()));
  try {
    FolderLock l(d.string(), StaleLock::refuse, nullptr);
    ADD_FAILURE() << "a stale lock was taken silently";
  } catch (const FolderBusy& e) {
    EXPECT_NE(std::string(e.what()).find("which is no longer running"), std::string::npos) << e.what();
  }
  std::ostringstream note;
  FolderLock l(d.string(), StaleLock::take_over, &note);
  EXPECT_NE(note.str().find("taking over the lock of pid " + std::to_string(child)), std::string::npos) << note.str();
}

// The manifest lists what was written; --overwrite removes only those regular files, never behind a link.
TEST(ResultFolder, OverwriteRemovesOnlyRecordedRegularFilesAndFollowsNoLink) {
  const fs::path d = scratch("overwrite"), outside = scratch("outside");
  std::ofstream(outside / "step_000000.vtu") << "not shelldyn's";
  {
    FolderLock l(d.string(), StaleLock::refuse, nullptr);
    fs::create_directories(d / "fields");
    record_output((d / "history.csv").string());
    std::ofstream(d / "history.csv") << "step\n";
    record_output((d / "fields" / "step_000000.vtu").string());
    std::ofstream(d / "fields" / "step_000000.vtu") << "vtu";
    record_output((d / "history.csv").string());  // recorded once
  }
  EXPECT_EQ(read(d / manifest_file_name()), "history.csv\nfields/step_000000.vtu\n");
  std::ofstream(d / "notes.txt") << "mine";
  fs::remove_all(d / "fields");
  fs::create_directory_symlink(outside, d / "fields");
  const auto removed = remove_recorded_outputs(d.string(), {"run.json"});
  EXPECT_EQ(removed, std::vector<std::string>{"history.csv"});
  EXPECT_TRUE(fs::exists(outside / "step_000000.vtu"));
  EXPECT_TRUE(fs::exists(d / "notes.txt"));
  EXPECT_FALSE(fs::exists(d / manifest_file_name()));
}

// history.csv rows are whole lines on the file at every moment (one write each, nothing buffered).
TEST(ResultFolder, HistoryRowsAreOnTheFileAsSoonAsWritten) {
  const fs::path d = scratch("history");
  HistoryWriter w((d / "history.csv").string(), {}, {});
  HistoryRow r;
  r.t = 0.5;
  w.write(r);
  const std::string text = read(d / "history.csv");
  EXPECT_EQ(static_cast<long long>(text.size()), w.bytes());
  EXPECT_EQ(text.back(), '\n');
  w.sync();
}

TEST(ResultFolder, InputsMustBeRegularFiles) {
  const fs::path d = scratch("fifo");
  ASSERT_EQ(mkfifo((d / "pipe").c_str(), 0600), 0);
  try {
    require_regular_file((d / "pipe").string(), "case file");
    ADD_FAILURE() << "a FIFO was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is a FIFO (named pipe), not a regular file; give the case file itself"),
              std::string::npos) << e.what();
  }
  EXPECT_THROW(require_regular_file(d.string(), "case file"), std::runtime_error);  // a folder
  std::ofstream(d / "ok") << "x";
  EXPECT_NO_THROW(require_regular_file((d / "ok").string(), "case file"));
}

TEST(ResultFolder, MemoryEstimateRefusesWithTheEstimate) {
  EXPECT_EQ(parse_memory_size("4G"), 4LL << 30);
  EXPECT_EQ(parse_memory_size("512M"), 512LL << 20);
  EXPECT_EQ(parse_memory_size("2e9"), 2000000000LL);
  EXPECT_THROW(parse_memory_size("lots"), std::invalid_argument);
  EXPECT_THROW(parse_memory_size("-1G"), std::invalid_argument);
  set_memory_limit(64LL << 20);
  EXPECT_NO_THROW(check_memory_estimate(1000, 250, "", "coarser"));
  try {
    check_memory_estimate(1000000, 250000, "case.yaml:3: mesh", "use a coarser mesh");
    ADD_FAILURE() << "a model far above --max-memory was accepted";
  } catch (const std::runtime_error& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.rfind("case.yaml:3: mesh: 1000000 nodes need at least ", 0), 0u) << w;
    EXPECT_NE(w.find("more than --max-memory 64 MiB; use a coarser mesh"), std::string::npos) << w;
  }
  set_memory_limit(0);
}
