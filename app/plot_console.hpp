// The console's figure key: the figures of the session it is running (app/plot_command.hpp),
// written from a console background task while the engine goes on.
#pragma once

#include <filesystem>
#include <string>

#include "ui/session_gateway.hpp"

namespace bellows {

/// Draws the figures of `snapshot`'s trials into a new folder under `root`, named after its saved
/// session (or "console") and the number of trials, e.g. `2024-05-01_12-00-00_paper_iteration_0012`.
/// Returns the folder. Throws InputError / EnvironmentError with the reason.
std::string write_console_figures(const ui::SessionSnapshot& snapshot, const std::filesystem::path& root);

/// Where the console writes figures: `figures` beside the default session data directory
/// (~/.local/share/bellows/figures); empty when there is no such directory.
std::filesystem::path default_figures_root();

}  // namespace bellows
