// Everything the operator and the engine did, with times: what the log screen shows and what a
// saved session keeps. Bounded, oldest entries dropped first.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <ctime>
#include <deque>
#include <string>

namespace bellows::ui {

enum class LogSource { kOperator, kEngine, kLearner, kSession, kDevice };

const char* to_string(LogSource source);

struct LogEntry {
  std::string clock;     // local wall-clock time, "HH:MM:SS"
  double engine_time_s;  // engine time when it happened (negative: not known)
  LogSource source;
  std::string text;
  bool important = false;  // faults, refusals: highlighted
  bool routine = false;    // a trial's own state changes: only on the log screen
  std::string time_utc;    // ISO 8601 ("2024-05-01T12:00:00.123Z"), for saved sessions
  int iteration = 0;       // the iteration next to run when it happened
  std::string event_kind;  // saved as a session event of its own kind ("model-refit"); empty: a
                           // line of the console-log event (or not saved: LogSource::kLearner)
};

/// The kind of session event a law's note is saved as (what `bellows run` records too).
inline constexpr const char* kModelRefitEvent = "model-refit";

/// The current time as ISO 8601 UTC with milliseconds.
std::string utc_timestamp();

class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 2000) : capacity_(capacity) {}
  void add(LogEntry entry) {
    entries_.push_back(std::move(entry));
    while (entries_.size() > capacity_) entries_.pop_front();
    ++total_;
  }
  const std::deque<LogEntry>& entries() const { return entries_; }
  void set_last_event_kind(std::string kind) {
    if (!entries_.empty()) entries_.back().event_kind = std::move(kind);
  }
  std::size_t total() const { return total_; }  // ever added, for "new entries" checks

 private:
  std::size_t capacity_;
  std::deque<LogEntry> entries_;
  std::size_t total_ = 0;
};

inline std::string utc_timestamp() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &utc);
  char out[40];
  std::snprintf(out, sizeof out, "%s.%03dZ", stamp, static_cast<int>(millis));
  return out;
}

inline const char* to_string(LogSource source) {
  switch (source) {
    case LogSource::kOperator:
      return "operator";
    case LogSource::kEngine:
      return "engine";
    case LogSource::kLearner:
      return "learner";
    case LogSource::kSession:
      return "session";
    case LogSource::kDevice:
      return "device";
  }
  return "?";
}

}  // namespace bellows::ui
