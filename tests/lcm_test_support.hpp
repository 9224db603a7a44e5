// Helpers for the LCM tests: a recorder of everything on a bus, a private network namespace for
// multicast between processes, and child processes to start, wait for and kill.
#pragma once

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "devices/lcm_io_thread.hpp"

extern char** environ;

namespace bellows::testing {

/// One message seen on a bus.
struct Recorded {
  std::string channel;
  std::vector<std::uint8_t> bytes;
  double received_s = 0.0;  // monotonic
};

/// Records every message on the channels matching `pattern` (an LcmEndpoint: runs on the thread
/// that owns the bus; read it from any thread).
class BusRecorder final : public LcmEndpoint {
 public:
  explicit BusRecorder(std::string pattern = ".*") : pattern_(std::move(pattern)) {}
  void attach(lcm::LCM& bus) override { subscribe(bus, pattern_, 100000); }
  double service(lcm::LCM*, double now_s) override { return now_s + 0.05; }

  std::vector<Recorded> messages() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  std::vector<Recorded> on(const std::string& channel) const {
    std::vector<Recorded> out;
    for (auto& m : messages()) {
      if (m.channel == channel) out.push_back(m);
    }
    return out;
  }
  /// The latest message on `channel`, if any.
  std::optional<Recorded> last(const std::string& channel) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = messages_.rbegin(); it != messages_.rend(); ++it) {
      if (it->channel == channel) return *it;
    }
    return std::nullopt;
  }
  std::size_t size() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return messages_.size();
  }
  void clear() {
    const std::lock_guard<std::mutex> lock(mutex_);
    messages_.clear();
  }

 private:
  void on_message(const char* channel, const void* data, std::size_t size) override {
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    const std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back({channel, std::vector<std::uint8_t>(bytes, bytes + size), monotonic_s()});
  }

  std::string pattern_;
  mutable std::mutex mutex_;
  std::vector<Recorded> messages_;
};

/// Waits up to `timeout_s` for `condition`, polling. True if it came true.
inline bool eventually(const std::function<bool()>& condition, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

/// Moves this process into a private network namespace (what `unshare -n` does) with loopback up,
/// multicast on and a 224.0.0.0/4 route on it, so that LCM's UDP multicast works between the
/// processes started from here and never leaves the namespace. Returns "" on success, else why not
/// (the caller skips). Changes nothing outside the new namespace.
inline std::string enter_private_network_namespace() {
  struct stat before {};
  if (stat("/proc/self/ns/net", &before) != 0) return "no /proc/self/ns/net";
  if (unshare(CLONE_NEWNET) != 0) {
    return std::string("cannot make a network namespace: unshare(CLONE_NEWNET): ") + std::strerror(errno) +
           " (needs root or CAP_SYS_ADMIN)";
  }
  struct stat after {};
  if (stat("/proc/self/ns/net", &after) != 0 || after.st_ino == before.st_ino)
    return "the network namespace did not change";
  // Only now, inside the new namespace.
  if (std::system("ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo") != 0) {
    return "cannot set up loopback multicast in the namespace (is iproute2 installed?)";
  }
  return "";
}

/// In a test body (namespace bellows): enters a private network namespace, or skips the test saying why not.
#define ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP()                                      \
  do {                                                                                 \
    const std::string why_not = testing::enter_private_network_namespace();            \
    if (!why_not.empty()) GTEST_SKIP() << "no private network namespace: " << why_not; \
  } while (false)

/// A child process with stdout and stderr in files.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::filesystem::path& out, const std::filesystem::path& err)
      : out_(out), err_(err) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> args = argv;
    std::vector<char*> raw;
    for (auto& a : args) raw.push_back(a.data());
    raw.push_back(nullptr);
    if (posix_spawnp(&pid_, raw[0], &actions, nullptr, raw.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() {
    if (running()) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool started() const { return pid_ > 0; }
  bool running() const { return pid_ > 0 && !status_; }
  void signal(int number) const {
    if (running()) kill(pid_, number);
  }
  /// The exit status (128 + signal if killed), or nothing if it is still running after `timeout_s`.
  std::optional<int> wait(double timeout_s) {
    if (status_ || pid_ <= 0) return status_;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return status_;
      }
      if (std::chrono::steady_clock::now() > deadline) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  std::string out() const { return read(out_); }
  std::string err() const { return read(err_); }

 private:
  static std::string read(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::filesystem::path out_, err_;
};

}  // namespace bellows::testing
