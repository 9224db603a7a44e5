// One piece of work off the UI thread (building a learning law, a learning update, saving or
// opening a session): the UI thread starts it with copies of what it needs and polls for the
// result, so it never waits and keeps its heartbeat going.
#pragma once

#include <chrono>
#include <future>
#include <utility>

namespace bellows::ui {

template <typename T>
class BackgroundTask {
 public:
  BackgroundTask() = default;
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;
  ~BackgroundTask() { wait(); }

  template <typename Work>
  void start(Work&& work) {
    future_ = std::async(std::launch::async, std::forward<Work>(work));
  }
  bool busy() const { return future_.valid(); }
  bool ready() const {
    return future_.valid() && future_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  }
  /// The result (rethrows the work's exception). Only after ready().
  T take() { return future_.get(); }
  void wait() {
    if (future_.valid()) future_.wait();
  }

 private:
  std::future<T> future_;
};

}  // namespace bellows::ui
