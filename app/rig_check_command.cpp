#include "app/rig_check_command.hpp"

#include <cmath>
#include <cstdio>
#include <istream>
#include <memory>
#include <numbers>
#include <optional>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/device_factory.hpp"
#include "app/run_command.hpp"
#include "app/trajectory_file.hpp"
#include "app/rig_check_limits.hpp"
#include "app/rig_profile_write.hpp"
#include "app/signals.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_io_thread.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"
#include "engine/operator/valve_test.hpp"
#include "sessions/session_store.hpp"
#include "sessions/session_writer.hpp"

namespace bellows {
namespace {

std::string line_of(const char* pattern, auto... values) {
  char text[400];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

// The calibrated values as the engine sees them (every device has these).
nlohmann::json reading_json(const SensorReading& r) {
  return {{"angle_deg", r.joint[0].angle_rad * kDegPerRad},
          {"chamber_a_bar", r.joint[0].chamber_bar[0]},
          {"chamber_b_bar", r.joint[0].chamber_bar[1]},
          {"supply_bar", r.supply_bar},
          {"temperature_K", r.temperature_K}};
}

void print_inputs(const RawInputs& raw, const SensorReading& r, const std::string& device, std::ostream& progress) {
  if (raw.count == 0) {
    progress << "inputs (" << device << ": no volts, the values the engine reads):\n"
             << line_of(
                    "  angle        %9.3f deg\n  chamber A    %9.4f bar\n  chamber B    %9.4f bar\n"
                    "  supply       %9.4f bar\n  temperature  %9.2f K\n",
                    r.joint[0].angle_rad * kDegPerRad, r.joint[0].chamber_bar[0], r.joint[0].chamber_bar[1],
                    r.supply_bar, r.temperature_K);
    return;
  }
  progress << "inputs (" << device << "): raw volts -> calibrated value\n";
  for (int i = 0; i < raw.count; ++i) {
    const RawInput& in = raw.inputs[i];
    progress << line_of("  %-12s %8.4f V -> %10.4f %s\n", in.name, in.volts, in.value, in.unit);
  }
}

// The angle read now (the mean of `readings` fresh readings, the arm at rest where it should read zero)
// becomes the profile's zero: the new zero is the old one plus what the device reads with it. A link
// that brings no fresh reading for `patience_s` ends it: one line, the profile unchanged.
nlohmann::json zero_the_angle(EngineDriver& driver, OpenedDevice& rig, const DeviceParameters& device, int readings,
                              double patience_s, double tick_s, std::ostream& progress) {
  double sum_rad = 0.0;
  int count = 0;
  double last_time_s = -INFINITY;
  const auto patience_ticks = static_cast<std::uint64_t>(std::ceil(patience_s / tick_s));
  std::optional<std::uint64_t> fresh_tick;  // the engine's tick of the last fresh reading
  TickRecord tick;
  while (count < readings) {
    if (stop_requested().load(std::memory_order_relaxed))
      throw InputError("--zero-angle stopped: the profile is unchanged");
    driver.await();
    if (!driver.core().read_snapshot(tick)) continue;
    if (!fresh_tick) fresh_tick = tick.tick;
    if (!(tick.reading.time_s > last_time_s)) {  // fresh readings only
      if (tick.tick - *fresh_tick > patience_ticks) {
        throw EnvironmentError(line_of(
            "--zero-angle: no fresh reading from %s for %.1f s ([t7] connect_timeout_s): the profile is unchanged",
            rig.where().c_str(), patience_s));
      }
      continue;
    }
    fresh_tick = tick.tick;
    last_time_s = tick.reading.time_s;
    if (!std::isfinite(tick.reading.joint[0].angle_rad))
      throw InputError("--zero-angle: the angle reads not-a-number: check its input");
    sum_rad += tick.reading.joint[0].angle_rad;
    ++count;
  }
  const double previous_rad = rig.angle_zero_rad().value_or(0.0);
  const double read_rad = sum_rad / count;
  progress << "angle zero: " << zero_rig_angle(rig, device.rig_profile, read_rad) << " (mean of " << count
           << " readings)\n";
  return {{"profile", device.rig_profile},
          {"read_deg", read_rad * kDegPerRad},
          {"readings", count},
          {"previous_rad", previous_rad},
          {"angle_zero_rad", rig.angle_zero_rad().value_or(0.0)}};
}

// The session a rig check is recorded in, like a run's: its manifest holds the device (with its
// address and rig profile) and the configuration; its events, each input (raw volts and
// calibrated value), each valve's verdict, the angle zero and the outcome. Saved at every event.
class RigCheckSession {
 public:
  RigCheckSession(const RigCheckOptions& options, const Configuration& config, const DeviceParameters& device,
                  const OpenedDevice& rig) {
    if (options.no_save) return;
    SessionManifest header;
    header.device = device.kind;
    header.device_info = rig.session_info();
    header.configuration = config;
    header.events.push_back({utc_now(), 0, "start",
                             std::string(kPurpose) + (options.zero_angle    ? ": zeroing the angle"
                                                      : options.inputs_only ? ": the inputs"
                                                                            : ": the inputs and the valve test")});
    // A session has a trajectory: the one `bellows run` learns by default.
    const Trajectory trajectory =
        resolve_trajectory(RunOptions{}.trajectory, config.timing.sample_s(), config.trajectory);
    const std::filesystem::path data_dir =
        options.data_dir.empty() ? default_data_dir() : std::filesystem::path(options.data_dir);
    writer_.emplace(SessionWriter::create(data_dir, options.session_name, std::move(header), trajectory, kPurpose));
  }
  void record(const std::string& kind, const std::string& message) {
    if (writer_) writer_->record_event(kind, message);
  }
  std::string path() const { return writer_ ? writer_->directory().string() : std::string(); }

 private:
  static constexpr const char* kPurpose = "bellows rig check";
  std::optional<SessionWriter> writer_;
};

// The LCM rig's own limits (app/rig_check_limits.hpp): announced, then the command timeout provoked.
// Prints a line each, records them in the session; returns how many failed.
int check_rig_limits(EngineDriver& driver, LcmDevice& device, const Configuration& config, bool valves_finished,
                     RigCheckSession& session, nlohmann::json& report, std::ostream& progress) {
  RigAnnouncedLimits announced;
  const double wait_until_s = monotonic_s() + 2.0 * kIoLimitsPeriod_s + 0.5;  // announced once a second
  bool have = device.read_announced_limits(announced);
  while (!have && monotonic_s() < wait_until_s && !stop_requested().load(std::memory_order_relaxed)) {
    driver.await();
    have = device.read_announced_limits(announced);
  }
  std::vector<LimitVerdict> verdicts = judge_announced_limits(have ? &announced : nullptr, config, device.joints());
  TimeoutObservation timeout;
  if (valves_finished) {
    progress << "command timeout: the chambers take a little air, every valve closed, then the engine falls silent ..."
             << std::endl;
    timeout = provoke_command_timeout(driver, device, config, link_lag_s(device.health()), &stop_requested());
  } else {
    timeout.not_provoked = "the valve test stopped early";
  }
  verdicts.push_back(judge_command_timeout(timeout, config));
  progress << "limits (what the rig announces and does, against this configuration):\n";
  int failed = 0;
  for (const LimitVerdict& v : verdicts) {
    if (v.pass()) {
      progress << line_of("  %-26s pass  %s, expected %s\n", v.name.c_str(), v.found.c_str(), v.expected.c_str());
    } else {
      ++failed;
      progress << "FAIL " << v.name << ": " << v.problem << "\n";
    }
    session.record("rig-limit-check", v.pass() ? v.name + " pass: " + v.found + ", expected " + v.expected
                                               : v.name + " FAIL: " + v.problem);
  }
  if (timeout.tripped) {
    progress << line_of(
        "  the rig's trip: fault_bits %d, session %s, command_seq %lld (last sent %lld); chambers %.3f/%.3f -> "
        "%.3f/%.3f bar; served again after %.0f ms; the engine said %s: %s\n",
        timeout.trip.fault_bits, timeout.trip.session_id == timeout.session_id ? "this one" : "another",
        static_cast<long long>(timeout.trip.command_seq), static_cast<long long>(timeout.last_command_seq),
        timeout.before.joint[0].chamber_bar[0], timeout.before.joint[0].chamber_bar[1],
        timeout.after.joint[0].chamber_bar[0], timeout.after.joint[0].chamber_bar[1], timeout.served_again_s * 1e3,
        fault_name(timeout.engine_fault), timeout.engine_detail.c_str());
  }
  report["limits"] = limits_json(verdicts, have ? &announced : nullptr, &timeout);
  return failed;
}

void record_inputs(const RawInputs& raw, const SensorReading& r, RigCheckSession& session) {
  if (raw.count == 0) {
    session.record("rig-input", line_of("no volts (simulated): angle %.3f deg, chamber A %.4f bar, chamber B %.4f bar, "
                                        "supply %.4f bar, temperature %.2f K",
                                        r.joint[0].angle_rad * kDegPerRad, r.joint[0].chamber_bar[0],
                                        r.joint[0].chamber_bar[1], r.supply_bar, r.temperature_K));
    return;
  }
  for (int i = 0; i < raw.count; ++i) {
    const RawInput& in = raw.inputs[i];
    session.record("rig-input", line_of("%s %.4f V -> %.4f %s", in.name, in.volts, in.value, in.unit));
  }
}

}  // namespace

int rig_check_command(const RigCheckOptions& options, std::istream& in, std::ostream& out, std::ostream& progress) {
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  require_single_joint_arm(config.arm, "`bellows rig check` tests the valves of one joint's rig");
  const DeviceParameters device = resolve_device(options.device, config.device);
  if (options.zero_angle && (device.kind != "t7" || device.rig_profile.empty())) {  // before anything opens
    throw InputError(
        "--zero-angle writes the rig profile's angle_zero_rad: it needs --device t7 and --rig-profile FILE "
        "(the built-in paper-rig profile cannot be written; copy profiles/paper-rig.toml)");
  }
  const std::unique_ptr<OpenedDevice> rig = open_device(device, config, options.seed, options.rt, 0,
                                                        std::filesystem::path(options.config_path).parent_path());
  EngineCore core(rig->device(), config.controller, config.timing, config.safety);
  std::unique_ptr<EngineDriver> driver;
  RealtimeLoop* loop = nullptr;
  if (rig->needs_real_time()) {
    auto realtime = std::make_unique<RealtimeLoop>(core, rig->device(), 1.0);
    loop = realtime.get();
    driver = std::move(realtime);
    loop->start(options.rt);
  } else {
    driver = std::make_unique<SimulatedClock>(core, rig->device());
  }
  struct StopLoop {  // vents on every way out
    RealtimeLoop* loop;
    OpenedDevice& rig;
    ~StopLoop() {
      if (loop != nullptr) loop->stop();
      rig.stop();
    }
  } stop_loop{loop, *rig};
  require_served(*rig, config.lcm.connect_timeout_s, stop_requested());

  // The inputs of a tick that began once the rig served (a tick before may show none yet: zeros).
  driver->await();
  driver->await();
  TickRecord latest;
  while (!core.read_snapshot(latest)) driver->await();
  const RawInputs raw = rig->device().raw_inputs();
  progress << "rig check on " << device.kind << " (" << rig->where() << ")"
           << (rig->rig_profile_name().empty() ? "" : ", rig profile " + rig->rig_profile_name()) << "\n";
  print_inputs(raw, latest.reading, device.kind, progress);
  nlohmann::json report = {{"device", device.kind},
                           {"rig_profile", rig->rig_profile_name()},
                           {"reading", reading_json(latest.reading)},
                           {"inputs", nlohmann::json::array()}};
  for (int i = 0; i < raw.count; ++i) {
    report["inputs"].push_back({{"name", raw.inputs[i].name},
                                {"volts", raw.inputs[i].volts},
                                {"value", raw.inputs[i].value},
                                {"unit", raw.inputs[i].unit}});
  }
  RigCheckSession session(options, config, device, *rig);
  record_inputs(raw, latest.reading, session);
  report["session"] = session.path().empty() ? nlohmann::json(nullptr) : nlohmann::json(session.path());
  if (!session.path().empty()) progress << "session: " << session.path() << "\n";
  if (options.zero_angle) {
    report["angle_zero"] = zero_the_angle(*driver, *rig, device, config.rig_check.zero_readings,
                                          config.t7.connect_timeout_s, config.timing.tick_s, progress);
    session.record("angle-zero", line_of("angle_zero_rad %.6f -> %.6f (the arm read %+.3f deg) in %s",
                                         report["angle_zero"]["previous_rad"].get<double>(),
                                         report["angle_zero"]["angle_zero_rad"].get<double>(),
                                         report["angle_zero"]["read_deg"].get<double>(), device.rig_profile.c_str()));
    if (options.json) out << report.dump() << std::endl;
    return 0;
  }
  if (options.inputs_only) {
    if (options.json) out << report.dump() << std::endl;
    return 0;
  }

  const RigCheckParameters& check = config.rig_check;
  if (!options.yes) {
    progress << line_of(
                    "The valve test opens each valve alone for %.3f s (inlet A, inlet B, outlet A, outlet B); the "
                    "arm will move. Clear it, then type y to go on: ",
                    check.valve_pulse_s)
             << std::flush;
    std::string answer;
    std::getline(in, answer);
    if (answer.empty() || (answer[0] != 'y' && answer[0] != 'Y')) {
      session.record("finish", "valve test not confirmed: no valve was opened");
      throw InputError("valve test not confirmed: no valve was opened (--yes skips the question)");
    }
  }
  const ValveTestReport result =
      run_valve_test(*driver, check, config.safety, config.controller.gas.ambient_bar, config.model.volume_gain_per_rad,
                     &stop_requested(), link_lag_s(rig->device().health()));
  report["valves"] = nlohmann::json::array();
  int failed = 0;
  progress << "valves:\n";
  for (const ValveVerdict& v : result.valves) {
    if (v.pass) {
      progress << line_of("  %-9s pass  (own chamber %+.3f bar, other %+.3f bar)%s\n", valve_name(v.valve),
                          v.own_change_bar, v.other_change_bar, repeat_note(v).c_str());
    } else {
      ++failed;
      progress << "FAIL " << valve_name(v.valve) << ": " << v.problem << repeat_note(v) << "\n";
    }
    session.record("valve-test",
                   v.pass ? line_of("%s pass (own chamber %+.4f bar, other %+.4f bar)%s", valve_name(v.valve),
                                    v.own_change_bar, v.other_change_bar, repeat_note(v).c_str())
                          : std::string(valve_name(v.valve)) + " FAIL: " + v.problem + repeat_note(v));
    report["valves"].push_back({{"valve", valve_name(v.valve)},
                                {"pass", v.pass},
                                {"tested", v.tested},
                                {"own_change_bar", v.own_change_bar},
                                {"other_change_bar", v.other_change_bar},
                                {"pulses", v.pulses},
                                {"problem", v.problem}});
  }
  if (!result.aborted.empty()) progress << "stopped early: " << result.aborted << "\n";
  // An LCM rig's own limits: what it announces, and its command timeout provoked (after the valves:
  // a rig whose valves are wrong is named first).
  LcmDevice* lcm = rig->lcm_device();
  const int limits_failed =
      lcm != nullptr && stop_signal() == 0
          ? check_rig_limits(*driver, *lcm, config, result.aborted.empty(), session, report, progress)
          : 0;
  const std::string valves_outcome =
      failed == 0 ? "every valve passed" : line_of("%d of %d valves failed", failed, kValveCount);
  const std::string limits_outcome =
      lcm == nullptr       ? ""
      : limits_failed == 0 ? ", every limit passed"
                           : line_of(", %d limit check%s failed", limits_failed, limits_failed == 1 ? "" : "s");
  session.record("finish", (result.aborted.empty() ? std::string() : "stopped early: " + result.aborted + "; ") +
                               valves_outcome + limits_outcome);
  progress << "rig check: " << valves_outcome << limits_outcome << std::endl;
  const bool all_pass = result.all_pass() && limits_failed == 0;
  report["aborted"] = result.aborted;
  report["all_pass"] = all_pass;
  if (options.json) out << report.dump() << std::endl;
  if (stop_signal() != 0) return 128 + stop_signal();
  return all_pass ? 0 : kExitRigCheckFailed;
}

}  // namespace bellows
