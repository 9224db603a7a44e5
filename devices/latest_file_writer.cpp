#include "devices/latest_file_writer.hpp"

#include <filesystem>
#include <fstream>
#include <utility>

namespace bellows {

LatestFileWriter::LatestFileWriter(std::string path) : path_(std::move(path)), thread_([this] { write_loop(); }) {}

LatestFileWriter::~LatestFileWriter() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void LatestFileWriter::post(std::string text) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(text);
    has_pending_ = true;
  }
  changed_.notify_all();
}

void LatestFileWriter::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return !has_pending_ && !writing_; });
}

void LatestFileWriter::write_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return has_pending_ || stopping_; });
    if (!has_pending_) return;  // stopping, and everything posted is written
    const std::string text = std::move(pending_);
    has_pending_ = false;
    writing_ = true;
    lock.unlock();
    const std::string temporary = path_ + ".tmp";
    {
      std::ofstream out(temporary, std::ios::trunc);
      out << text;
    }
    std::error_code ignored;  // a status file that cannot be written is not worth stopping a server for
    std::filesystem::rename(temporary, path_, ignored);
    lock.lock();
    writing_ = false;
    changed_.notify_all();
  }
}

}  // namespace bellows
