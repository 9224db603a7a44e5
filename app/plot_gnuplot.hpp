// Runs gnuplot (Debian's gnuplot-nox: no display needed; cairo PNG and PDF, SVG) on a script in a
// folder, as a child process. Not on the real-time side: called from the CLI or a console
// background task.
#pragma once

#include <filesystem>

namespace bellows {

/// Runs `gnuplot SCRIPT` with `directory` as its working directory. EnvironmentError when gnuplot
/// is not installed; InputError with gnuplot's first error line when the script fails.
void run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& directory);

}  // namespace bellows
