// `bellows sessions list|show|export|rm|rename`: the saved sessions (newest first), one session's
// summary and RMS per iteration, exports to CSV or MATLAB, removing (after a confirmation) and
// renaming a session. `--json` prints one JSON value on stdout for scripts.
// A bad session is an InputError (one line on stderr, exit status 2), except in `list`, which
// flags it and goes on with the others.
#pragma once

#include <iosfwd>
#include <string>

namespace bellows {

struct SessionsOptions {
  std::string data_dir;  // empty: the default data directory
  std::string session;   // show, export: a directory, or a session name in the data directory
  std::string format = "csv";
  std::string output;       // export: the file to write; empty: <session name>.<format> here
  std::string mat_version;  // export --format mat: "5" (also when empty) or "7.3"
  bool force = false;       // export: replace existing files
  bool yes = false;         // rm: no confirmation question
  std::string new_name;     // rename
  bool json = false;
};

int sessions_list_command(const SessionsOptions& options, std::ostream& out, std::ostream& err);
int sessions_show_command(const SessionsOptions& options, std::ostream& out);
int sessions_export_command(const SessionsOptions& options, std::ostream& out);
/// Asks on `err` and reads the answer from `in` unless `options.yes`; 1 when not confirmed.
int sessions_rm_command(const SessionsOptions& options, std::istream& in, std::ostream& out, std::ostream& err);
int sessions_rename_command(const SessionsOptions& options, std::ostream& out);

}  // namespace bellows
