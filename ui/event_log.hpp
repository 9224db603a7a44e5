// Everything the operator and the engine did, with times: what the log screen shows and what a
// saved session keeps. Bounded, oldest entries dropped first.
#pragma once

#include <cstddef>
#include <deque>
#include <string>

namespace bellows::ui {

enum class LogSource { kOperator, kEngine, kLearner, kSession };

const char* to_string(LogSource source);

struct LogEntry {
  std::string clock;     // local wall-clock time, "HH:MM:SS"
  double engine_time_s;  // engine time when it happened (negative: not known)
  LogSource source;
  std::string text;
  bool important = false;  // faults, refusals: highlighted
  bool routine = false;    // a trial's own state changes: only on the log screen
};

class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 2000) : capacity_(capacity) {}
  void add(LogEntry entry) {
    entries_.push_back(std::move(entry));
    while (entries_.size() > capacity_) entries_.pop_front();
    ++total_;
  }
  const std::deque<LogEntry>& entries() const { return entries_; }
  std::size_t total() const { return total_; }  // ever added, for "new entries" checks

 private:
  std::size_t capacity_;
  std::deque<LogEntry> entries_;
  std::size_t total_ = 0;
};

inline const char* to_string(LogSource source) {
  switch (source) {
    case LogSource::kOperator: return "operator";
    case LogSource::kEngine: return "engine";
    case LogSource::kLearner: return "learner";
    case LogSource::kSession: return "session";
  }
  return "?";
}

}  // namespace bellows::ui
