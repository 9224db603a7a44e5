// A file that holds the latest of a stream of texts, written on a thread of its own. Whoever posts
// never waits for the disk: a server that answers requests in real time (t7-sim) would otherwise
// stall behind a truncate or a rename while another process loads the disk, and a client would see
// a T7 that does not answer. Texts posted faster than the disk takes them are skipped, never queued:
// only the latest counts. Each write replaces the file atomically (temporary, then rename), so a
// reader never sees half a text.
#pragma once

#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace bellows {

class LatestFileWriter {
 public:
  explicit LatestFileWriter(std::string path);
  /// Writes the text posted last (if not yet written), then stops the thread.
  ~LatestFileWriter();
  LatestFileWriter(const LatestFileWriter&) = delete;
  LatestFileWriter& operator=(const LatestFileWriter&) = delete;

  /// Makes `text` the file's next content; returns at once.
  void post(std::string text);
  /// Returns when the text posted last is in the file (for a final write that must land).
  void flush();

 private:
  void write_loop();

  const std::string path_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::string pending_;
  bool has_pending_ = false;
  bool writing_ = false;
  bool stopping_ = false;
  std::thread thread_;  // last: starts after everything it uses
};

}  // namespace bellows
