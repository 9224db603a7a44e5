// t7-sim's status file is written on a thread of its own (devices/latest_file_writer.hpp): the
// thread that answers Modbus requests posts the text and goes on, however long the disk takes.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "devices/latest_file_writer.hpp"

namespace bellows {
namespace {

std::filesystem::path fresh_directory(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string contents(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(LatestFileWriter, HoldsTheTextPostedLastAndNoTemporary) {
  const auto dir = fresh_directory("latest-file-writer");
  const auto path = dir / "status.json";
  {
    LatestFileWriter writer(path.string());
    for (int i = 0; i < 200; ++i) writer.post("text " + std::to_string(i) + "\n");
    writer.flush();
    EXPECT_EQ(contents(path), "text 199\n");
    writer.post("the last\n");
  }  // the destructor writes what was posted last
  EXPECT_EQ(contents(path), "the last\n");
  EXPECT_FALSE(std::filesystem::exists(dir.string() + "/status.json.tmp"));
  std::filesystem::remove_all(dir);
}

// The temporary is a FIFO nobody reads: the writer's open blocks, as a write to a stalled disk
// would. Posting must still return at once (a writer on the poster's thread never would).
TEST(LatestFileWriter, PostingNeverWaitsForAWriteThatIsStuck) {
  const auto dir = fresh_directory("latest-file-writer-stuck");
  const auto path = dir / "status.json";
  const std::string temporary = path.string() + ".tmp";
  ASSERT_EQ(::mkfifo(temporary.c_str(), 0600), 0);
  LatestFileWriter writer(path.string());
  writer.post("first\n");  // the writer thread takes it and blocks opening the FIFO
  auto posts = std::async(std::launch::async, [&] {
    for (int i = 0; i < 100; ++i) writer.post("later " + std::to_string(i) + "\n");
  });
  // A generous bound on a hang, not a measure of speed: the posts take microseconds.
  EXPECT_EQ(posts.wait_for(std::chrono::seconds(20)), std::future_status::ready) << "a post waited for the disk";
  {
    std::ifstream fifo(temporary);  // unblocks the writer: it writes the text it took, and renames the FIFO
    std::stringstream taken;
    taken << fifo.rdbuf();
    EXPECT_TRUE(taken.str() == "first\n" || taken.str().rfind("later ", 0) == 0) << taken.str();
  }
  writer.post("the end\n");  // the FIFO may have taken the latest so far: one more, into a plain file
  writer.flush();
  EXPECT_EQ(contents(path), "the end\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace bellows
