// A report that could not be written is not a success: at exit, standard output is flushed and
// checked, and a failed write (a full disk, /dev/full, an I/O error) becomes one line on stderr
// and exit status 4 (EnvironmentError), instead of a silent exit 0 with the report lost.
#pragma once

namespace bellows {

/// Registers the check to run at exit (std::atexit; after main returns, before stdio closes).
/// Call once, first thing in main.
void check_standard_output_at_exit();

}  // namespace bellows
