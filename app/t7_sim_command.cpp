#include "app/t7_sim_command.hpp"

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <ostream>

#include "app/config_file.hpp"
#include "app/rig_profile_file.hpp"
#include "app/signals.hpp"
#include "app/t7_wiring.hpp"
#include "devices/t7_sim_server.hpp"
#include "engine/base/errors.hpp"

namespace bellows {

namespace {
// The simulated T7 answers and runs its watchdog like hardware: real-time where the system allows
// (the same priority as the engine's device I/O threads), plain scheduling where it refuses.
constexpr int kSimPriority = 70;
}  // namespace

int t7_sim_command(const T7SimCommandOptions& options, std::ostream& out) {
  if (options.duration_s < 0.0) throw InputError("--duration must not be negative");
  T7SimOptions sim;
  parse_host_port(options.listen, kDefaultT7SimPort, sim.host, sim.port, "--listen", 0);  // port 0: any free one
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  sim.plant = config.plant;
  sim.profile = rig_profile_or_default(options.rig_profile);
  sim.plant.pwm_period_s = 1.0 / sim.profile.pwm_frequency_hz;  // the arm's valves follow the profile's PWM
  sim.seed = options.seed;
  sim.status_path = options.status_path;
  sim.limits = RigLimits::from(config);  // the rig's own limits, as io-sim's
  sim.swapped_chambers = options.swapped_chambers;
  sim.no_supply = options.no_supply;
  sim.silent_after_s = options.silent_after_s;
  sim.stall_after_s = options.stall_after_s;
  sim.stall_s = options.stall_s;
  if (options.product != "t7" && options.product != "t7-pro")
    throw InputError("--product must be t7 or t7-pro, not '" + options.product + "'");
  sim.product = options.product == "t7" ? t7::Product::kT7 : t7::Product::kT7Pro;
  sim.nagle = options.nagle;
  sim.answer_after_s = options.answer_after_s;
  sim.trickle_after_s = options.trickle_after_s;
  sim.trickle_byte_s = options.trickle_byte_s;
  sim.silent_reads = options.silent_reads;
  sim.streaming = options.streaming;
  sim.halve_roll_after_s = options.halve_roll_after_s;
  if (!options.dead_valve.empty()) {
    for (ValveRole role : kValveRoles) {
      if (options.dead_valve == to_string(role)) sim.dead_valve = role;
    }
    if (!sim.dead_valve)
      throw InputError("--dead-valve must be inlet_a, inlet_b, outlet_a or outlet_b, not '" + options.dead_valve + "'");
  }
  T7SimServer server(sim);
  out << "t7-sim: a simulated " << t7::to_string(sim.product) << " (rig profile " << sim.profile.name << ") on "
      << sim.host << ":" << server.port();
  if (sim.swapped_chambers) out << "; drill: chambers swapped";
  if (sim.dead_valve) out << "; drill: " << to_string(*sim.dead_valve) << " dead";
  if (sim.no_supply) out << "; drill: no supply";
  if (sim.silent_after_s >= 0.0) out << "; drill: silent after " << sim.silent_after_s << " s";
  if (sim.stall_after_s >= 0.0)
    out << "; drill: one answer " << sim.stall_s << " s late after " << sim.stall_after_s << " s";
  if (sim.nagle) out << "; drill: Nagle";
  if (sim.silent_reads) out << "; drill: reads unanswered";
  if (sim.streaming) out << "; drill: another program streams (STREAM_ENABLE 1)";
  if (sim.halve_roll_after_s >= 0.0) out << "; drill: clock 0's roll halved after " << sim.halve_roll_after_s << " s";
  if (sim.answer_after_s > 0.0) out << "; drill: every answer " << sim.answer_after_s << " s late";
  if (sim.trickle_after_s >= 0.0)
    out << "; drill: answers trickle after " << sim.trickle_after_s << " s, " << sim.trickle_byte_s << " s a byte";
  out << std::endl;
  sched_param param{};
  param.sched_priority = kSimPriority;
  const bool realtime = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  if (!realtime) out << "t7-sim: real-time scheduling refused; answers may come late under load" << std::endl;
  const auto start = std::chrono::steady_clock::now();
  server.run(
      [&] {
        return stop_requested().load(std::memory_order_relaxed) ||
               (options.duration_s > 0.0 &&
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= options.duration_s);
      },
      [&](const std::string& line) { out << line << std::endl; });
  const T7SimStatus s = server.status();
  out << "t7-sim: " << s.requests << " requests answered, " << s.exceptions << " with an exception (" << s.refusals
      << " refused by LabJack's rules), " << s.watchdog_actions << " watchdog actions, at most " << s.max_clients
      << " connections at once, " << s.refused_connections << " refused; " << s.late_answers
      << " answers more than 0.5 ms after LabJack's time (at most " << s.answer_late_max_s * 1e3 << " ms)" << std::endl;
  return 0;
}

}  // namespace bellows
