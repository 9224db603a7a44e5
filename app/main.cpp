// bellows: the lab console and its headless commands.
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/identify_command.hpp"
#include "app/run_command.hpp"
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

  bellows::IdentifyOptions identify;
  CLI::App* identify_cmd =
      app.add_subcommand("identify", "Identification trial on the simulated arm; fits kappa, omega0 and damping");
  identify_cmd->add_option("--config", identify.config_path, "TOML configuration file");
  identify_cmd->add_option("--signal", identify.signal, "Excitation: chirp or steps (default: [identify] signal)");
  identify_cmd->add_option("--seed", identify.seed, "Seed of the simulated arm's noise")->capture_default_str();
  identify_cmd->add_option("--write-model", identify.write_model_path, "Write the fit into this config file's [model]");
  identify_cmd->add_flag("--json", identify.json, "Print one JSON object on stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }

  try {
    if (run_cmd->parsed()) return bellows::run_command(run, std::cout, run.json ? std::cerr : std::cout);
    if (identify_cmd->parsed()) {
      return bellows::identify_command(identify, std::cout, identify.json ? std::cerr : std::cout);
    }
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
