#include "app/io_sim_command.hpp"

#include <cmath>
#include <filesystem>
#include <memory>
#include <ostream>

#include <nlohmann/json.hpp>

#include "app/config_file.hpp"
#include "app/lcm_url.hpp"
#include "app/run_io.hpp"
#include "app/signals.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_auth.hpp"
#include "devices/lcm_rig_server.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "devices/swapped_chambers.hpp"
#include "engine/base/errors.hpp"

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

  // One joint: the single-joint simulated arm, as always. An [arm] chain (preset or its own keys): the J-joint chain.
  std::unique_ptr<SimulatedArm> single_joint;
  std::unique_ptr<SimulatedArmChain> chain;
  int joints = 1;
  double integration_step_s = config.plant.integration_step_s;
  if (!config.arm.has_chain()) {
    single_joint = std::make_unique<SimulatedArm>(config.plant, options.seed);
  } else {
    const PneumaticChainParameters chain_parameters = pneumatic_chain_of(config.plant, config.arm);
    chain = std::make_unique<SimulatedArmChain>(chain_parameters, options.seed);
    joints = chain->joints();
    integration_step_s = chain_parameters.chain.integration_step_s;
  }
  Device& plant = single_joint ? static_cast<Device&>(*single_joint) : *chain;
  SwappedChambers crossed(plant);
  Device& arm = options.swapped_chambers ? static_cast<Device&>(crossed) : plant;
  RigServerParameters params;
  params.period_s = config.timing.tick_s;
  params.command_timeout_s = config.lcm.rig_timeout_s;
  params.seq_window = config.lcm.seq_window;
  params.limits = RigLimits::from(config);
  params.command_timeout_enforced = !options.no_command_timeout;
  params.stepped = options.stepped;
  if (options.stepped) params.command_timeout_s = config.lcm.lockstep_timeout_s;  // the engine's wait for an answer
  params.key = load_lcm_key(config.lcm.key_file, std::filesystem::path(options.config_path).parent_path());
  params.log = [&progress](const std::string& line) { progress << "io-sim: " << line << std::endl; };
  const bool keyed = params.key.present();
  RigServer rig(arm, joints, integration_step_s, std::move(params), random_nonzero_id());
  LcmIoThread io(url, {&rig});

  io.on_open([&] {
    const std::string which =
        joints == 1 ? std::string() : " '" + config.arm.name() + "' of " + std::to_string(joints) + " joints";
    progress << "io-sim: serving the simulated arm" << which << " on " << url << " (rig " << rig.stats().rig_id
             << ", state every " << config.timing.tick_s * 1e3 << " ms, vents after "
             << (options.stepped ? config.lcm.lockstep_timeout_s : config.lcm.rig_timeout_s) * 1e3
             << " ms without commands, chambers above " << RigLimits::from(config).pressure_ceiling_bar
             << " bar and beyond " << config.lcm.rig_angle_limit_deg << " deg; "
             << (keyed ? "commands authenticated" : "no key: commands NOT authenticated") << ")"
             << (options.stepped ? "; stepped: its time advances one period per command (run --clock lockstep)" : "")
             << (options.swapped_chambers ? "; drill: chambers A and B swapped" : "")
             << (options.no_command_timeout ? "; drill: no command timeout (it never vents by itself)" : "")
             << std::endl;
  });
  const double start_s = monotonic_s();
  io.run(
      [&] {
        return stop_requested().load(std::memory_order_relaxed) ||
               (options.duration_s > 0.0 && monotonic_s() - start_s >= options.duration_s);
      },
      options.rt, kRigPriority);

  const RigServerStats s = rig.stats();
  progress << "io-sim: " << s.commands.accepted << " commands applied, " << s.commands.ignored() << " ignored ("
           << s.commands.foreign << " of other sessions, " << s.commands.out_of_order << " out of sequence, "
           << s.commands.unauthenticated << " unauthenticated, " << s.commands.old_version << " of protocol version 1"
           << (s.commands.other_joints > 0
                   ? ", " + std::to_string(s.commands.other_joints) + " for an arm of another joint count"
                   : "")
           << "), " << s.sessions_served << " sessions, " << s.timeouts << " timeouts, " << s.pressure_limit_trips
           << " + " << s.angle_limit_trips << " pressure + angle limit trips, " << s.states_published
           << " states published; valves vented" << std::endl;
  if (options.json) {
    nlohmann::json report = {{"rig_id", s.rig_id},
                             {"joints", joints},
                             {"url", url},
                             {"rt", io.rt_granted() ? "fifo" : "other"},
                             {"commands", receive_counts_json(s.commands)},
                             {"states_published", s.states_published},
                             {"sessions_served", s.sessions_served},
                             {"timeouts", s.timeouts},
                             {"not_addressed", s.not_addressed},
                             {"vents_obeyed_out_of_sequence", s.vents_obeyed_out_of_sequence},
                             {"pressure_limit_trips", s.pressure_limit_trips},
                             {"angle_limit_trips", s.angle_limit_trips},
                             {"authenticated", keyed},
                             {"missed_periods", s.missed_periods}};
    out << report.dump() << std::endl;
  }
  return 0;
}

}  // namespace bellows
