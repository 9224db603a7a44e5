// What a device's I/O thread writes to stderr while the console owns the terminal goes to the log,
// not across the screen (a T7 link that stopped answering painted its lines over the console).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "tests/console_fixture.hpp"
#include "ui/stderr_capture.hpp"

namespace bellows::ui {
namespace {

ino_t stderr_inode() {
  struct stat s {};
  fstat(STDERR_FILENO, &s);
  return s.st_ino;
}

TEST(UiStderrCapture, AnotherThreadsLinesAreDrainedWholeAndStderrComesBack) {
  const ino_t before = stderr_inode();
  std::vector<std::string> lines;
  {
    StderrCapture capture;
    ASSERT_TRUE(capture.active());
    EXPECT_NE(stderr_inode(), before);  // a pipe now
    std::thread io([] {
      std::fprintf(stderr, "bellows: t7 link 127.0.0.1:502: no answer within 2.7 ms\n");
      std::fprintf(stderr, "bellows: t7 link 127.0.0.1:502 ans");  // a line in two writes
      std::fprintf(stderr, "wers again\n");
    });
    io.join();
    lines = capture.drain();
    EXPECT_TRUE(capture.drain().empty());  // each line once
  }
  EXPECT_EQ(stderr_inode(), before);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "bellows: t7 link 127.0.0.1:502: no answer within 2.7 ms");
  EXPECT_EQ(lines[1], "bellows: t7 link 127.0.0.1:502 answers again");
}

TEST(UiStderrCapture, AFullPipeNeverStallsTheWriter) {
  StderrCapture capture;
  ASSERT_TRUE(capture.active());
  const std::string line(1000, 'x');
  for (int i = 0; i < 200; ++i) std::fprintf(stderr, "%s\n", line.c_str());  // 200 kB > a pipe's 64 kB
  const std::vector<std::string> lines = capture.drain();
  EXPECT_GT(lines.size(), 0u);
  EXPECT_LT(lines.size(), 200u);  // the rest were dropped, not waited for
}

TEST(UiStderrCapture, TheDevicesLinesGoToTheLogAsTheDevicesWithoutTheProgramName) {
  testing::ConsoleFixture f;
  f.console->device_said("bellows: t7 link 127.0.0.1:502: no answer within 2.7 ms (the exchange's deadline)");
  const LogEntry& last = f.state().log.entries().back();
  EXPECT_EQ(last.source, LogSource::kDevice);
  EXPECT_EQ(last.text, "t7 link 127.0.0.1:502: no answer within 2.7 ms (the exchange's deadline)");
  EXPECT_STREQ(to_string(last.source), "device");
}

}  // namespace
}  // namespace bellows::ui
