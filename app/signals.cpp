#include "app/signals.hpp"

#include <csignal>

#include "engine/rt/engine_core.hpp"

namespace bellows {
namespace {
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
std::atomic<EngineCore*> g_target{nullptr};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free &&
                  std::atomic<EngineCore*>::is_always_lock_free,
              "signal handlers may only touch lock-free atomics");

extern "C" void on_stop_signal(int signal_number) {
  // Vent first: request_emergency_stop() is one lock-free atomic add, safe in a handler.
  if (EngineCore* core = g_target.load(std::memory_order_acquire)) core->request_emergency_stop();
  g_signal.store(signal_number, std::memory_order_relaxed);
  g_stop.store(true, std::memory_order_release);
}

void stop_on(int signal_number) {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(signal_number, &action, nullptr);
}
}  // namespace

void install_stop_signal_handlers() {
  // SIGQUIT too: Ctrl-\ would otherwise end the process at once, the valves as they were (on a T7 until its
  // watchdog acts), the session's last save not made and the terminal left in the console's modes.
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) stop_on(signal_number);
}

void guard_device_command_signals() {
  stop_on(SIGPIPE);
  std::signal(SIGTSTP, SIG_IGN);
}

const std::atomic<bool>& stop_requested() { return g_stop; }
int stop_signal() { return g_signal.load(std::memory_order_relaxed); }

const char* stop_signal_name() {
  switch (stop_signal()) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGQUIT:
      return "SIGQUIT";
    case SIGPIPE:
      return "SIGPIPE";
    case 0:
      return "no signal";
  }
  return "a signal";
}

StopSignalTarget::StopSignalTarget(EngineCore& core) {
  g_target.store(&core, std::memory_order_release);
  if (g_stop.load(std::memory_order_acquire)) core.request_emergency_stop();  // arrived before this
}

StopSignalTarget::~StopSignalTarget() { g_target.store(nullptr, std::memory_order_release); }

}  // namespace bellows
