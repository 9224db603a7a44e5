#include "app/io_sim_command.hpp"

#include <cmath>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/lcm_url.hpp"
#include "app/run_io.hpp"
#include "app/signals.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_server.hpp"
#include "engine/errors.hpp"

namespace bellows {
namespace {
// The rig's loop is its real-time part; same priority as the engine's LCM I/O thread.
constexpr int kRigPriority = 70;
}  // namespace

int io_sim_command(const IoSimOptions& options, std::ostream& out, std::ostream& progress) {
  if (!std::isfinite(options.duration_s) || options.duration_s < 0.0) {
    throw InputError("--duration must be a finite number of seconds >= 0");
  }
  const Configuration config = options.config_path.empty() ? Configuration{} : load_config_file(options.config_path);
  const std::string url = options.lcm_url.empty() ? kDefaultLcmUrl : options.lcm_url;
  check_lcm_url(url, "--lcm");

  SimulatedArm arm(config.plant, options.seed);
  RigServerParameters params;
  params.period_s = config.timing.tick_s;
  params.command_timeout_s = config.lcm.rig_timeout_s;
  RigServer rig(arm, params, LcmDevice::random_session_id());
  LcmIoThread io(url, {&rig});

  progress << "io-sim: serving the simulated arm on " << url << " (rig " << rig.stats().rig_id << ", state every "
           << params.period_s * 1e3 << " ms, vents after " << params.command_timeout_s * 1e3 << " ms without commands)"
           << std::endl;
  const double start_s = monotonic_s();
  io.run(
      [&] {
        return stop_requested().load(std::memory_order_relaxed) ||
               (options.duration_s > 0.0 && monotonic_s() - start_s >= options.duration_s);
      },
      options.rt, kRigPriority);

  const RigServerStats s = rig.stats();
  progress << "io-sim: " << s.commands.accepted << " commands applied, " << s.commands.ignored() << " ignored, "
           << s.sessions_served << " sessions, " << s.timeouts << " timeouts, " << s.states_published
           << " states published; valves vented" << std::endl;
  if (options.json) {
    nlohmann::json report = {{"rig_id", s.rig_id},
                             {"url", url},
                             {"rt", io.rt_granted() ? "fifo" : "other"},
                             {"commands", receive_counts_json(s.commands)},
                             {"states_published", s.states_published},
                             {"sessions_served", s.sessions_served},
                             {"timeouts", s.timeouts},
                             {"missed_periods", s.missed_periods}};
    out << report.dump() << std::endl;
  }
  return 0;
}

}  // namespace bellows
