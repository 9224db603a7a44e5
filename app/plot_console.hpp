// The console's figure key: the figures of the session it is running, drawn like `bellows sessions
// plot` from the session's files on disk (app/plot_command.hpp), on a console background task
// while the engine goes on. The console keeps only its newest trials in memory; the files hold
// every one.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace bellows {

/// Runs a read of the session's files while nothing writes them (StoreSessionGateway::read_quietly).
using QuietRead = std::function<void(const std::function<void()>&)>;

/// Draws the figures of the first `iterations` iterations of the saved session `session_location`
/// into a new folder under `root`, named after the session and the last iteration, e.g.
/// `2024-05-01_12-00-00_paper_iteration_0012` (`_2`, `_3`, ... when drawn again). Returns what
/// the console logs: the folder, and for the paper trajectory whether the paper's curve is in it.
/// Throws InputError / EnvironmentError with the reason.
std::string write_console_figures(const std::string& session_location, int iterations,
                                  const std::filesystem::path& root, const QuietRead& quietly);

/// Where the console writes figures: `figures` beside the default session data directory
/// (~/.local/share/bellows/figures); empty when there is no such directory.
std::filesystem::path default_figures_root();

}  // namespace bellows
