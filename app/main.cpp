// bellows: the lab console and its headless commands.
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/run_command.hpp"
#include "app/sessions_command.hpp"
#include "engine/errors.hpp"

namespace {
constexpr int kExitBadInput = 2;
}

int main(int argc, char** argv) {
  CLI::App app{"bellows: iterative learning control for a pneumatic soft robotic arm"};
  app.require_subcommand(0, 1);

  bellows::RunOptions run;
  CLI::App* run_cmd = app.add_subcommand("run", "Run trials headless on simulated time, learning between them");
  run_cmd->add_option("--trajectory", run.trajectory, "Library name (paper, steps, sine) or a CSV file")
      ->capture_default_str();
  run_cmd->add_option("--iterations", run.iterations, "Learning iterations after the feedback-only trial")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  run_cmd->add_option("--config", run.config_path, "TOML configuration file");
  run_cmd->add_option("--seed", run.seed, "Seed of the simulated arm's noise")->capture_default_str();
  run_cmd->add_flag("--json", run.json, "Print one JSON object on stdout");
  CLI::Option* no_save = run_cmd->add_flag("--no-save", run.no_save, "Do not save the session");
  run_cmd->add_option("--data-dir", run.data_dir,
                      "Where sessions are saved (default $XDG_DATA_HOME/bellows/sessions or ~/.local/share/bellows/sessions)")
      ->excludes(no_save);
  CLI::Option* name = run_cmd->add_option("--name", run.session_name, "Session name (default: start time and trajectory)")
                          ->excludes(no_save);
  run_cmd->add_option("--resume", run.resume_dir, "Continue a saved session (a directory, or a name in the data directory)")
      ->excludes(no_save)
      ->excludes(name)
      ->excludes("--trajectory")
      ->excludes("--config")
      ->excludes("--seed");

  bellows::SessionsOptions sessions;
  CLI::App* sessions_cmd = app.add_subcommand("sessions", "List, show and export saved sessions");
  sessions_cmd->require_subcommand(1);
  const std::string data_dir_help = "Where sessions are saved (default $XDG_DATA_HOME/bellows/sessions)";
  CLI::App* list_cmd = sessions_cmd->add_subcommand("list", "A table of the saved sessions");
  CLI::App* show_cmd = sessions_cmd->add_subcommand("show", "One session: summary and RMS per iteration");
  CLI::App* export_cmd = sessions_cmd->add_subcommand("export", "Export a session to CSV or MATLAB (v7.3)");
  for (CLI::App* command : {list_cmd, show_cmd, export_cmd}) {
    command->add_option("--data-dir", sessions.data_dir, data_dir_help);
    command->add_flag("--json", sessions.json, "Print JSON on stdout");
  }
  for (CLI::App* command : {show_cmd, export_cmd}) {
    command->add_option("session", sessions.session, "Session directory, or a session name in the data directory")
        ->required();
  }
  export_cmd->add_option("--format", sessions.format, "csv or mat")->capture_default_str()->check(CLI::IsMember({"csv", "mat"}));
  export_cmd->add_option("--output", sessions.output, "File to write (default: <session>.csv or .mat here)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }

  try {
    if (run_cmd->parsed()) return bellows::run_command(run, std::cout, run.json ? std::cerr : std::cout);
    if (list_cmd->parsed()) return bellows::sessions_list_command(sessions, std::cout, std::cerr);
    if (show_cmd->parsed()) return bellows::sessions_show_command(sessions, std::cout);
    if (export_cmd->parsed()) return bellows::sessions_export_command(sessions, std::cout);
    std::cout << app.help();
    return 0;
  } catch (const bellows::InputError& error) {
    std::cerr << "bellows: " << error.what() << std::endl;
    return kExitBadInput;
  } catch (const std::exception& error) {
    std::cerr << "bellows: internal error: " << error.what() << std::endl;
    return 1;
  }
}
