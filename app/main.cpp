// bellows: the lab console and its headless commands. The command line is wired here; each
// command's work is in its own file. Every error ends in one line `bellows: ...` on stderr, its text
// passed through printable() (engine/base/printable_text.hpp), and the exit status its type carries
// (engine/base/errors.hpp): 0 done, 1 an internal error (untyped: a bug), 2 bad input, 3 an engine
// fault, 4 the environment refused, 5 `rig check` found a failing valve or rig limit, 128 + N
// stopped by signal N after venting and saving what finished (app/signals.hpp).
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/cli_checks.hpp"
#include "app/completion_command.hpp"
#include "app/config_file.hpp"
#include "app/console_command.hpp"
#include "app/identify_command.hpp"
#include "app/io_sim_command.hpp"
#include "app/memory_policy.hpp"
#include "app/rig_check_command.hpp"
#include "app/plot_command.hpp"
#include "app/plot_style.hpp"
#include "app/run_command.hpp"
#include "app/sessions_command.hpp"
#include "app/t7_sim_command.hpp"
#include "app/trajectories_command.hpp"
#include "app/signals.hpp"
#include "app/standard_output.hpp"
#include "devices/lcm_channels.hpp"
#include "engine/base/cancellation.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "engine/config/learning_transfer.hpp"
#include "engine/trial/trajectory.hpp"
#include "sessions/session.hpp"
#include "sessions/session_store.hpp"

using bellows::kExitBadInput;

namespace {
// Longest --duration / --exit-after / --silent-after: a year, far beyond any run, far below a double's range.
constexpr double kLongestRunSeconds = 365.0 * 24 * 3600;
}  // namespace

// A function-try-block: an exception while the command line is built (a bug) or while an error is
// reported still ends in one line and status 1, never std::terminate's abort.
int main(int argc, char** argv) try {
  bellows::bound_allocator_retention();
  bellows::check_standard_output_at_exit();
  CLI::App app{"bellows: iterative learning control for a pneumatic soft robotic arm",
               "bellows"};  // not argv[0]: no build path
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "bellows " + bellows::program_version());  // as sessions record it

  bellows::RunOptions run;
  CLI::App* run_cmd = app.add_subcommand(
      "run", "Run trials headless (simulated time on the simulated arm, real time on a rig), learning between them");
  run_cmd
      ->add_option("--trajectory", run.trajectory,
                   "Library name: " + bellows::trajectory_library_summary() +
                       "; or a CSV file (an [arm] preset of J joints: paperJ by default)")
      ->capture_default_str();
  run_cmd
      ->add_option("--iterations", run.iterations,
                   "K: iteration 0 (feedback only), then K learning iterations: 0..K "
                   "(with --resume: K after the newest)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  run_cmd->add_option("--config", run.config_path, "TOML configuration file");
  run_cmd->add_option("--seed", run.seed, "Seed of the simulated arm's noise")
      ->capture_default_str()
      ->check(bellows::unsigned_whole_number());
  run_cmd->add_flag("--json", run.json, "Print one JSON object on stdout (progress then goes to stderr)");
  CLI::Option* verbose = run_cmd->add_flag("--verbose,-v", run.verbose,
                                           "A progress line per iteration (default on a terminal: one line, redrawn)");
  run_cmd->add_flag("--quiet,-q", run.quiet, "Print nothing but errors (and the JSON with --json)")->excludes(verbose);
  run_cmd
      ->add_option("--clock", run.clock,
                   "sim: simulated time, as fast as possible; wall: the real-time loop (default: wall on a rig "
                   "(--device lcm, t7), sim on the simulated arm); lockstep: --device lcm, each tick waits for the "
                   "rig's answer (a stepped simulator: io-sim --stepped)")
      ->check(CLI::IsMember({"sim", "wall", "lockstep"}));
  run_cmd->add_option("--speed", run.speed, "Wall clock with the simulated arm: 1, 2, 5, 10 or max")
      ->capture_default_str()
      ->check(CLI::IsMember({"1", "2", "5", "10", "max"}));
  const std::map<std::string, bellows::RealtimeMode> rt_modes = {{"enforce", bellows::RealtimeMode::kEnforce},
                                                                 {"try", bellows::RealtimeMode::kTry},
                                                                 {"off", bellows::RealtimeMode::kOff}};
  run_cmd->add_option("--rt", run.rt, "Real-time scheduling: enforce (refuse without), try, off")
      ->transform(bellows::named_choice(rt_modes))
      ->type_name("MODE")
      ->default_str("try");
  CLI::Option* no_save = run_cmd->add_flag("--no-save", run.no_save, "Do not save the session");
  run_cmd
      ->add_option(
          "--data-dir", run.data_dir,
          "Where sessions are saved (default $XDG_DATA_HOME/bellows/sessions or ~/.local/share/bellows/sessions)")
      ->excludes(no_save);
  CLI::Option* name =
      run_cmd->add_option("--name", run.session_name, "Session name (default: start time and trajectory)")
          ->excludes(no_save)
          ->check(CLI::Validator(
              [](const std::string& value) {
                try {
                  bellows::validate_session_name(value);  // '' too: never silently the default
                  return std::string();
                } catch (const bellows::InputError& error) {
                  return std::string(error.what());
                }
              },
              ""));
  run_cmd
      ->add_option("--resume", run.resume_dir,
                   "Continue a saved session (a directory, or a name in the data directory)")
      ->excludes(no_save)
      ->excludes(name)
      ->excludes("--trajectory")
      ->excludes("--config")
      ->excludes("--seed");

  run_cmd
      ->add_option("--transfer-from", run.transfer_from,
                   "Start from what these saved sessions taught (a directory or a name; repeatable)")
      ->excludes("--resume");
  run_cmd
      ->add_option("--transfer-method", run.transfer_method,
                   "How: " + bellows::transfer_method_names() + " (docs/learning-laws.md)")
      ->capture_default_str();

  bellows::SessionsOptions sessions;
  CLI::App* sessions_cmd = app.add_subcommand("sessions", "List, show, export, plot, rename and remove saved sessions");
  sessions_cmd->require_subcommand(1);
  const std::string data_dir_help = "Where sessions are saved (default $XDG_DATA_HOME/bellows/sessions)";
  CLI::App* list_cmd = sessions_cmd->add_subcommand("list", "A table of the saved sessions");
  CLI::App* show_cmd = sessions_cmd->add_subcommand("show", "One session: summary and RMS per iteration");
  CLI::App* export_cmd = sessions_cmd->add_subcommand("export", "Export a session to CSV or a MATLAB MAT file");
  for (CLI::App* command : {list_cmd, show_cmd, export_cmd}) {
    command->add_option("--data-dir", sessions.data_dir, data_dir_help);
    command->add_flag("--json", sessions.json, "Print JSON on stdout");
  }
  for (CLI::App* command : {show_cmd, export_cmd}) {
    command->add_option("session", sessions.session, "Session directory, or a session name in the data directory")
        ->required();
  }
  export_cmd->add_option("--format", sessions.format, "csv or mat")
      ->capture_default_str()
      ->check(CLI::IsMember({"csv", "mat"}));
  export_cmd->add_option("--output", sessions.output, "File to write (default: <session>.csv or .mat here)");
  export_cmd
      ->add_option("--mat-version", sessions.mat_version,
                   "MAT file version: 5 (default; read everywhere) or 7.3 (HDF5)")
      ->check(CLI::IsMember({"5", "7.3"}));
  export_cmd->add_flag("--force", sessions.force, "Replace existing files");
  CLI::App* rm_cmd = sessions_cmd->add_subcommand("rm", "Remove a session (asks first unless --yes)");
  CLI::App* rename_cmd = sessions_cmd->add_subcommand("rename", "Give a session another name");
  for (CLI::App* command : {rm_cmd, rename_cmd}) {
    command->add_option("--data-dir", sessions.data_dir, data_dir_help);
    command->add_flag("--json", sessions.json, "Print JSON on stdout");
    command->add_option("session", sessions.session, "Session directory, or a session name in the data directory")
        ->required();
  }
  rm_cmd->add_flag("--yes,-y", sessions.yes, "Remove without asking");
  rename_cmd->add_option("new_name", sessions.new_name, "The new name")->required();
  bellows::PlotOptions plot;
  CLI::App* plot_cmd = sessions_cmd->add_subcommand("plot", "Figures of a session (PNG, SVG, PDF) drawn by gnuplot");
  plot_cmd->add_option("session", plot.session, "Session directory, or a session name in the data directory")
      ->required();
  plot_cmd->add_option("--data-dir", plot.data_dir, data_dir_help);
  plot_cmd->add_option("--output", plot.output, "Folder for the figures (default: <session>_figures here)");
  plot_cmd
      ->add_option("--iterations", plot.iterations,
                   "Iterations in the angle and u_ilc figures, e.g. 0,5,10 "
                   "(default: first, second, middle, last)")
      ->delimiter(',');
  plot_cmd->add_option("--trial", plot.trial, "Iteration whose pressures are drawn (default: the last)");
  plot_cmd->add_option("--formats", plot.formats, "png, svg and/or pdf, e.g. png,pdf")
      ->delimiter(',')
      ->default_str("png,svg")
      ->check(CLI::IsMember({"png", "svg", "pdf"}));
  plot_cmd
      ->add_option("--style", plot.style,
                   "Size and fonts: screen, paper-column (3.5 in wide, 8 pt) or paper-wide "
                   "(7.16 in, 8 pt)")
      ->capture_default_str()
      ->check(CLI::IsMember(bellows::figure_style_names()));
  plot_cmd->add_option("--paper", plot.paper,
                       "CSV (iteration,rms_deg) overlaid on the RMS figure "
                       "(default for the paper trajectory: the paper's curve, when available)");
  plot_cmd->add_flag("--no-paper", plot.no_paper, "No overlay on the RMS figure");
  plot_cmd->add_flag("--force", plot.force, "Replace existing figures");
  plot_cmd->add_flag("--json", plot.json, "Print JSON on stdout");
  bellows::add_device_options(*run_cmd, run.device, /*with_lcm=*/false);  // lcm and t7 run on the wall clock
  run_cmd->add_option("--lcm", run.lcm_url, "LCM bus URL: publish telemetry there (and find an lcm rig there)");
  CLI::Option* lcm_log = run_cmd
                             ->add_option("--lcm-log", run.lcm_log_file,
                                          "Keep an LCM event log of the telemetry: in FILE (a new file), or without "
                                          "FILE in the session directory")
                             ->expected(0, 1);

  bellows::IoSimOptions io_sim;
  CLI::App* io_sim_cmd = app.add_subcommand("io-sim", "Serve the simulated arm over LCM in real time, as a rig would");
  io_sim_cmd->add_option("--config", io_sim.config_path,
                         "TOML configuration file ([plant], [arm] preset, [timing], [lcm])");
  io_sim_cmd->add_option("--seed", io_sim.seed, "Seed of the simulated arm's noise")
      ->capture_default_str()
      ->check(bellows::unsigned_whole_number());
  io_sim_cmd->add_option("--lcm", io_sim.lcm_url, "LCM bus URL")->default_str(bellows::kDefaultLcmUrl);
  io_sim_cmd->add_option("--rt", io_sim.rt, "Real-time scheduling: enforce (refuse without), try, off")
      ->transform(bellows::named_choice(rt_modes))
      ->type_name("MODE")
      ->default_str("try");
  io_sim_cmd->add_option("--duration", io_sim.duration_s, "Stop after this many seconds (0: at SIGINT/SIGTERM)")
      ->capture_default_str()
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  io_sim_cmd->add_flag("--json", io_sim.json, "At exit, print the counters as one JSON object on stdout");
  io_sim_cmd->add_flag("--swapped-chambers", io_sim.swapped_chambers, "Drill: the tubes of chambers A and B swapped");
  io_sim_cmd->add_flag(
      "--stepped", io_sim.stepped,
      "Lockstep for `run --clock lockstep`: the arm's time advances one period per command, answered at once "
      "(no real rig can; the session drops after [lcm] lockstep_timeout_s without commands)");
  io_sim_cmd->add_flag("--no-command-timeout", io_sim.no_command_timeout,
                       "Drill: the rig announces its [lcm] rig_timeout_s but never vents when the commands stop");

  bellows::T7SimCommandOptions t7_sim;
  CLI::App* t7_sim_cmd = app.add_subcommand("t7-sim", "Serve the simulated arm as a LabJack T7 over Modbus TCP");
  t7_sim_cmd
      ->add_option("--listen", t7_sim.listen,
                   "HOST[:PORT] to listen on (port 0: any free one, named on the first line)")
      ->capture_default_str();
  t7_sim_cmd->add_option("--config", t7_sim.config_path, "TOML configuration file ([plant])");
  t7_sim_cmd->add_option("--rig-profile", t7_sim.rig_profile, "Rig profile (default: the paper rig's)");
  t7_sim_cmd->add_option("--seed", t7_sim.seed, "Seed of the simulated arm's noise")
      ->capture_default_str()
      ->check(bellows::unsigned_whole_number());
  t7_sim_cmd->add_option("--duration", t7_sim.duration_s, "Stop after this many seconds (0: at SIGINT/SIGTERM)")
      ->capture_default_str()
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd->add_option("--status", t7_sim.status_path,
                         "Keep the valve lines' state in this JSON file (docs/labjack-t7.md)");
  t7_sim_cmd->add_flag("--swapped-chambers", t7_sim.swapped_chambers,
                       "Drill: chamber A's and B's transmitters swapped");
  t7_sim_cmd->add_option("--dead-valve", t7_sim.dead_valve, "Drill: this valve pair never opens")
      ->check(CLI::IsMember({"inlet_a", "inlet_b", "outlet_a", "outlet_b"}));
  t7_sim_cmd->add_flag("--no-supply", t7_sim.no_supply, "Drill: the supply at ambient pressure");
  t7_sim_cmd
      ->add_option("--silent-after", t7_sim.silent_after_s,
                   "Drill: the link falls silent this many seconds after the first request")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd
      ->add_option("--stall-after", t7_sim.stall_after_s,
                   "Drill: one answer comes late (--stall-s) this many seconds after the first request")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd->add_option("--stall-s", t7_sim.stall_s, "Drill: how late that answer comes")
      ->capture_default_str()
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd
      ->add_option("--product", t7_sim.product,
                   "The T7 it is: t7 (resolution index 0..8) or t7-pro (0..12, the paper's)")
      ->capture_default_str()
      ->check(CLI::IsMember({"t7", "t7-pro"}));
  t7_sim_cmd->add_flag("--nagle", t7_sim.nagle, "Drill: answers with Nagle's algorithm (a T7 sends at once)");
  t7_sim_cmd->add_flag("--silent-reads", t7_sim.silent_reads,
                       "Drill: reads of the analog inputs go unanswered (no reading ever)");
  t7_sim_cmd->add_flag("--streaming", t7_sim.streaming,
                       "Drill: another program streams from it (STREAM_ENABLE reads 1, analog reads refused)");
  t7_sim_cmd
      ->add_option("--halve-roll-after", t7_sim.halve_roll_after_s,
                   "Drill: this many seconds after the first request, clock 0's roll value halves (another program): "
                   "wide duties are refused")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd
      ->add_option("--answer-after", t7_sim.answer_after_s,
                   "Drill: every answer this many seconds later (a slow device)")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd
      ->add_option("--trickle-after", t7_sim.trickle_after_s,
                   "Drill: this many seconds after the first request, answers trickle one byte at a time")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  t7_sim_cmd->add_option("--trickle-byte-s", t7_sim.trickle_byte_s, "Drill: the trickle's time per byte")
      ->capture_default_str()
      ->check(bellows::finite_seconds(kLongestRunSeconds));

  bellows::ConsoleOptions console;
  CLI::App* console_cmd = app.add_subcommand(
      "console", "The operator console (also: bellows with no arguments, or with the console's options alone)");
  bellows::add_device_options(*console_cmd, console.device);
  console_cmd->add_option("--speed", console.speed, "The simulated arm's time warp: 1, 2, 5, 10 or max")
      ->capture_default_str()
      ->check(CLI::IsMember({"1", "2", "5", "10", "max"}));
  console_cmd
      ->add_option("--clock", console.clock,
                   "wall (default): the real-time engine loop; sim: the simulated arm on simulated time, which "
                   "passes only while the engine has work (the same seed gives the numbers of bellows run)")
      ->check(CLI::IsMember({"sim", "wall"}));
  console_cmd->add_option("--config", console.config_path, "TOML configuration file");
  console_cmd
      ->add_option("--trajectory", console.trajectory,
                   "Library name: " + bellows::trajectory_library_summary() + "; or a CSV file")
      ->capture_default_str();
  console_cmd->add_option("--session", console.session_dir, "Open this saved session at start");
  console_cmd->add_option("--data-dir", console.data_dir,
                          "Where sessions are saved as the console goes (default $XDG_DATA_HOME/bellows/sessions or "
                          "~/.local/share/bellows/sessions)");
  console_cmd->add_option("--rt", console.rt, "Real-time scheduling of the engine loop: enforce, try, off")
      ->transform(bellows::named_choice(rt_modes))
      ->type_name("MODE")
      ->default_str("try");
  console_cmd->add_option("--seed", console.seed, "Seed of the simulated arm's noise")
      ->capture_default_str()
      ->check(bellows::unsigned_whole_number());
  console_cmd
      ->add_option("--stop-after-rises", console.stop_after_rises,
                   "A run of K iterations stops when the RMS rose this many times in a row")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  console_cmd->add_option("--exit-after", console.exit_after_s, "Close by itself after this many seconds (benchmarks)")
      ->check(bellows::finite_seconds(kLongestRunSeconds));
  console_cmd->add_flag("--no-color", console.no_color, "Attributes only, no colours (also: NO_COLOR set)");

  std::string config_path;
  CLI::App* config_cmd =
      app.add_subcommand("config", "Print the configuration (defaults, or --config on top of them) as TOML");
  config_cmd->add_option("--config", config_path, "TOML configuration file");
  bool config_markdown = false;
  config_cmd->add_flag("--markdown", config_markdown, "Print the key reference as Markdown tables instead");

  bellows::TrajectoriesOptions trajectories;
  CLI::App* trajectories_cmd = app.add_subcommand(
      "trajectories",
      "The trajectory library (joints, duration, samples); with a name or a CSV file, that trajectory as CSV");
  trajectories_cmd->add_option("trajectory", trajectories.trajectory,
                               "Library name: " + bellows::trajectory_library_summary() + "; or a CSV file to check");
  trajectories_cmd->add_option("--config", trajectories.config_path,
                               "TOML configuration file ([timing], [trajectory])");
  trajectories_cmd->add_option("--output", trajectories.output_path, "Write the CSV into this file instead of stdout");
  trajectories_cmd->add_flag("--force", trajectories.force, "Replace the --output file if it exists");

  bellows::install_stop_signal_handlers();

  bellows::IdentifyOptions identify;
  CLI::App* identify_cmd = app.add_subcommand(
      "identify", "Identification trials on the device; fits kappa, omega0 and damping (recorded in a session)");
  identify_cmd->add_option("--config", identify.config_path, "TOML configuration file");
  bellows::add_device_options(*identify_cmd, identify.device);
  identify_cmd->add_option("--rt", identify.rt, "Real-time scheduling of the engine loop (lcm, t7): enforce, try, off")
      ->transform(bellows::named_choice(rt_modes))
      ->type_name("MODE")
      ->default_str("try");
  identify_cmd->add_option("--signal", identify.signal, "Excitation: chirp or steps (default: [identify] signal)");
  identify_cmd->add_option("--seed", identify.seed, "Seed of the simulated arm's noise")
      ->capture_default_str()
      ->check(bellows::unsigned_whole_number());
  identify_cmd->add_option(
      "--write-model", identify.write_model_path,
      "Write the fit into the [model] of this config file or rig profile (created if missing; the rest of "
      "the file is kept; a file that holds a model already is refused without --force)");
  identify_cmd->add_flag("--force", identify.force, "--write-model: replace the model the file holds already");
  identify_cmd->add_flag("--json", identify.json, "Print one JSON object on stdout");
  CLI::Option* identify_no_save =
      identify_cmd->add_flag("--no-save", identify.no_save, "Do not record the identification in a session");
  identify_cmd
      ->add_option("--data-dir", identify.data_dir, "Where its session is saved (default: where runs save theirs)")
      ->excludes(identify_no_save);
  identify_cmd->add_option("--name", identify.session_name, "Session name (default: start time and the excitation)")
      ->excludes(identify_no_save);

  bellows::RigCheckOptions rig_check;
  CLI::App* rig_cmd = app.add_subcommand("rig", "The first day at the bench: check the rig's inputs and valves");
  rig_cmd->require_subcommand(1);
  CLI::App* rig_check_cmd = rig_cmd->add_subcommand(
      "check", "Raw inputs beside calibrated values, then each valve pulsed in turn, pass or fail");
  rig_check_cmd->add_option("--config", rig_check.config_path, "TOML configuration file ([device], [rig_check])");
  bellows::add_device_options(*rig_check_cmd, rig_check.device);
  rig_check_cmd->add_option("--seed", rig_check.seed, "Seed of the simulated arm's noise")->capture_default_str();
  rig_check_cmd
      ->add_option("--rt", rig_check.rt, "Real-time scheduling of the engine loop (lcm, t7): enforce, try, off")
      ->transform(bellows::named_choice(rt_modes))
      ->type_name("MODE")
      ->default_str("try");
  rig_check_cmd->add_flag("--yes", rig_check.yes, "Pulse the valves without asking (the operator has cleared the arm)");
  rig_check_cmd->add_flag("--inputs-only", rig_check.inputs_only, "Only show the inputs; open no valve");
  rig_check_cmd->add_flag(
      "--zero-angle", rig_check.zero_angle,
      "Make the angle read now the rig profile's zero (--device t7 --rig-profile FILE); open no valve");
  rig_check_cmd->add_flag("--json", rig_check.json, "Print one JSON object on stdout");
  CLI::Option* rig_no_save =
      rig_check_cmd->add_flag("--no-save", rig_check.no_save, "Do not record the check in a session");
  rig_check_cmd
      ->add_option("--data-dir", rig_check.data_dir,
                   "Where the check's session is saved (default: where runs save theirs)")
      ->excludes(rig_no_save);

  // Hidden (no group): what the build generates the bash completion with (app/completion_command.hpp).
  std::string completion_shell;
  CLI::App* completion_cmd = app.add_subcommand("completion", "Print the shell completion script")->group("");
  completion_cmd->add_option("shell", completion_shell, "bash")->required()->check(CLI::IsMember({"bash"}));

  // `bellows` alone is the console, so options given before any command are the console's: `bellows
  // --speed 10` is `bellows console --speed 10`, as a console such as htop takes its options directly.
  std::vector<const char*> args(argv, argv + argc);
  const std::string_view first = argc > 1 ? argv[1] : "";
  if (first.starts_with('-') && first != "-h" && first != "--help" && first != "--version") {
    args.insert(args.begin() + 1, "console");
  }
  try {
    app.parse(static_cast<int>(args.size()), args.data());
  } catch (const CLI::Success& help_or_version) {  // --help, --version: printed, exit 0
    return app.exit(help_or_version);
  } catch (const CLI::ParseError& error) {
    std::cerr << "bellows: " << bellows::printable(error.what(), bellows::kPrintableLine) << " (see --help)"
              << std::endl;
    return kExitBadInput;
  }

  try {
    run.lcm_log = lcm_log->count() > 0;
    run.speed_given = run_cmd->get_option("--speed")->count() > 0;
    run.trajectory_given = run_cmd->get_option("--trajectory")->count() > 0;
    run.progress_on_terminal = isatty(run.json ? STDERR_FILENO : STDOUT_FILENO) == 1;
    if (completion_cmd->parsed()) {
      std::cout << bellows::bash_completion(app);
      return 0;
    }
    // The commands that drive a device (run, identify, rig check, the console) stop as on SIGINT, vented
    // and saved, when their output's reader goes away, and are never suspended (Ctrl-Z); the others end
    // quietly as any tool.
    const bool drives_device = run_cmd->parsed() || identify_cmd->parsed() || rig_check_cmd->parsed() ||
                               console_cmd->parsed() || app.get_subcommands().empty();
    if (drives_device) bellows::guard_device_command_signals();
    if (run_cmd->parsed()) return bellows::run_command(run, std::cout, run.json ? std::cerr : std::cout);
    if (io_sim_cmd->parsed()) return bellows::io_sim_command(io_sim, std::cout, std::cerr);
    if (t7_sim_cmd->parsed()) return bellows::t7_sim_command(t7_sim, std::cout);
    if (config_cmd->parsed()) {
      const bellows::Configuration config =
          config_path.empty() ? bellows::Configuration{} : bellows::load_config_file(config_path);
      std::cout << (config_markdown ? bellows::config_to_markdown(config) : bellows::config_to_toml(config));
      return 0;
    }
    if (trajectories_cmd->parsed()) return bellows::trajectories_command(trajectories, std::cout);
    if (identify_cmd->parsed()) {
      return bellows::identify_command(identify, std::cout, identify.json ? std::cerr : std::cout);
    }
    if (rig_check_cmd->parsed()) {
      return bellows::rig_check_command(rig_check, std::cin, std::cout, rig_check.json ? std::cerr : std::cout);
    }
    if (list_cmd->parsed()) return bellows::sessions_list_command(sessions, std::cout, std::cerr);
    if (show_cmd->parsed()) return bellows::sessions_show_command(sessions, std::cout);
    if (export_cmd->parsed()) return bellows::sessions_export_command(sessions, std::cout);
    if (rm_cmd->parsed()) return bellows::sessions_rm_command(sessions, std::cin, std::cout, std::cerr);
    if (rename_cmd->parsed()) return bellows::sessions_rename_command(sessions, std::cout);
    if (plot_cmd->parsed()) return bellows::sessions_plot_command(plot, std::cout);
    // No subcommand (or `console`): the operator console.
    return bellows::console_command(console, std::cout);
  } catch (const bellows::Cancelled& stopped) {  // a long computation honoured SIGINT or SIGTERM
    std::cerr << "bellows: " << stopped.what() << std::endl;
    return 128 + (bellows::stop_signal() != 0 ? bellows::stop_signal() : SIGINT);
  } catch (const bellows::BellowsError& error) {
    std::cerr << "bellows: " << bellows::printable(error.what(), bellows::kPrintableLine) << std::endl;
    return error.exit_status();
  } catch (const std::exception& error) {
    std::cerr << "bellows: internal error: " << bellows::printable(error.what(), bellows::kPrintableLine) << std::endl;
    return 1;
  }
} catch (...) {
  std::fputs("bellows: internal error while starting or reporting an error\n", stderr);
  return 1;
}
