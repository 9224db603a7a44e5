// A console controller over a real engine and simulated arm on a simulated clock, driven by keys,
// for the console's tests; and sessions kept in memory.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <stdexcept>
#include <memory>
#include <string>
#include <thread>

#include "app/trajectory_file.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "ui/console_controller.hpp"
#include "ui/keys.hpp"

namespace bellows::testing {

/// Sessions kept in memory: what the console would save and open.
class MemorySessions final : public ui::SessionGateway {
 public:
  bool available() const override { return true; }
  /// Like the store: a new session, or what was added to the session named by the snapshot.
  std::string save(const ui::SessionSnapshot& snapshot) override {
    while (hold_saves) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a save still running
    const std::lock_guard<std::mutex> guard(mutex);
    const std::string location = snapshot.experiment.session_location.empty() ? "mem://" + std::to_string(saved.size())
                                                                              : snapshot.experiment.session_location;
    ui::SessionSnapshot merged = snapshot;
    if (const auto old = saved.find(location); old != saved.end()) {
      const auto& before = old->second.experiment.trials;
      merged.experiment.trials.assign(before.begin(), before.begin() + snapshot.first_trial);
      merged.experiment.trials.insert(merged.experiment.trials.end(), snapshot.experiment.trials.begin(),
                                      snapshot.experiment.trials.end());
      for (std::size_t i = 0; i < old->second.experiment.faults.size() && i < merged.experiment.faults.size(); ++i) {
        merged.experiment.faults[i] = old->second.experiment.faults[i];  // the saved black boxes, with their ticks
      }
      merged.events = old->second.events;
      const std::size_t first_new = snapshot.events_total - snapshot.events.size();
      for (std::size_t i = snapshot.experiment.saved_events > first_new ? snapshot.experiment.saved_events - first_new
                                                                        : 0;
           i < snapshot.events.size(); ++i) {
        merged.events.push_back(snapshot.events[i]);
      }
    }
    if (fail_saves) throw std::runtime_error("disk full (test)");
    merged.first_trial = 0;
    saved[location] = std::move(merged);
    ++saves;
    return location;
  }
  // Every call runs on a worker of its own (as the console's gateway calls do): each takes the lock.
  std::vector<ui::SessionListing> list() override {
    const std::lock_guard<std::mutex> guard(mutex);
    std::vector<ui::SessionListing> out;
    for (const auto& [location, s] : saved) {
      out.push_back({location, location, "2024-05-01 12:00", s.experiment.trajectory->name,
                     static_cast<int>(s.experiment.trials.size()), s.experiment.best_rms_deg(), "", s.device_name, ""});
    }
    return out;
  }
  ui::SessionSnapshot open(const std::string& location) override {
    const std::lock_guard<std::mutex> guard(mutex);
    ui::SessionSnapshot s = saved.at(location);
    s.experiment.session_location = location;
    return s;
  }
  ui::SessionSnapshot read_trials(const std::string& location) override { return open(location); }
  std::map<std::string, ui::SessionSnapshot> saved;
  std::atomic<int> saves{0};  // the tests read and set these while workers save
  std::atomic<bool> fail_saves{false};
  std::atomic<bool> hold_saves{false};
  std::mutex mutex;
};

struct ConsoleFixture {
  /// `gateway`: where sessions go (default: `sessions`, in memory). `device`: the engine drives it
  /// instead of `arm` (a test's own device). `write_figures`: the figure key's writer (default:
  /// none, the key says so). `start_trajectory`: the library trajectory it starts with (`paper2` for an
  /// arm2 device and configuration).
  explicit ConsoleFixture(const Configuration& c = Configuration{}, int stop_after_rises = 3,
                          ui::SessionGateway* gateway = nullptr, Device* device = nullptr,
                          std::function<std::string(const std::string&, int)> write_figures = {},
                          const std::string& start_trajectory = "paper")
      : config(c),
        arm(c.plant, 1),
        core(device != nullptr ? *device : arm, c.controller, c.timing, c.safety),
        clock(core, device != nullptr ? *device : arm) {
    ui::ConsoleEnvironment env;
    env.core = &core;
    env.telemetry = &core.add_telemetry_tap(4096);
    env.config = config;
    env.load_trajectory = [c](const std::string& name) {  // as app/console_command's
      Trajectory trajectory = resolve_trajectory(name, c.timing.sample_s(), c.trajectory);
      require_driven_joints(trajectory, c.arm);
      return trajectory;
    };
    env.sessions = gateway != nullptr ? gateway : &sessions;
    env.stop_after_rises = stop_after_rises;
    env.write_figures = std::move(write_figures);
    env.clock_text = [] { return std::string("12:00:00"); };
    console =
        std::make_unique<ui::ConsoleController>(env, library_trajectory(start_trajectory, c.timing.sample_s()), false);
    console->resize(120, 40);
    console->start(clock.now_s());
  }

  const ui::ConsoleState& state() const { return console->state(); }
  void key(int k) {
    console->handle_key(k, clock.now_s());
    console->update(clock.now_s());
  }
  void type(const std::string& keys) {
    for (char k : keys) key(k);
  }
  /// Lets engine time pass, the console keeping up every 25 ms of it, until `done` or the limits.
  bool pump_until(const std::function<bool()>& done, double max_engine_s = 400.0) {
    const auto wall_start = std::chrono::steady_clock::now();
    const double start = clock.now_s();
    while (!done()) {
      if (clock.now_s() - start > max_engine_s) return false;
      if (std::chrono::steady_clock::now() - wall_start > std::chrono::seconds(120)) return false;
      // Engine time stands still while the learner works or a save runs, so that runs are
      // deterministic: a batch's next trial waits for the autosave, and on a loaded machine a save
      // to disk (or a transfer's offer) can take longer than the engine time this loop would
      // otherwise race through.
      const bool waiting = console->state().run.phase == ui::RunProgress::Phase::kLearning ||
                           console->state().learner_busy || !console->state().law_ready || !console->saves_settled() ||
                           console->transfer_offer_pending();
      if (waiting) std::this_thread::sleep_for(std::chrono::microseconds(200));
      else clock.step(5);
      console->update(clock.now_s());
    }
    return true;
  }
  void pump_for(double engine_s) {
    const double until = clock.now_s() + engine_s;
    pump_until([&] { return clock.now_s() >= until; });
  }
  /// Until the trajectory file the path prompt took is read (off the UI thread): the prompt closed with
  /// its preview, or says why not.
  void wait_for_trajectory_file() {
    ASSERT_TRUE(pump_until([&] {
      return state().dialog.kind != ui::DialogKind::kTrajectoryPath || state().dialog.error.rfind("reading ", 0) != 0;
    }));
  }
  bool idle() const {
    return state().run.mode == ui::RunProgress::Mode::kIdle && state().engine_state != EngineState::kRunning;
  }
  void arm_valves() {
    ASSERT_TRUE(pump_until([&] { return state().law_ready; }));
    key('a');
    key('y');
    ASSERT_TRUE(pump_until([&] { return state().engine_state == EngineState::kArmed; }));
  }
  void run_batch(int k) {
    key('N');
    key(ui::key::kBackspace);
    key(ui::key::kBackspace);
    type(std::to_string(k));
    key(ui::key::kEnter);
    ASSERT_TRUE(pump_until([&] { return idle(); }));
  }
  bool logged(const std::string& fragment) const {
    for (const ui::LogEntry& e : state().log.entries()) {
      if (e.text.find(fragment) != std::string::npos) return true;
    }
    return false;
  }

  Configuration config;
  SimulatedArm arm;
  EngineCore core;
  SimulatedClock clock;
  MemorySessions sessions;
  std::unique_ptr<ui::ConsoleController> console;
};

}  // namespace bellows::testing
