// `bellows sessions list|show|export`: the saved sessions, one session's summary and RMS per
// iteration, and exports to CSV or MATLAB. `--json` prints one JSON value on stdout for scripts.
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
  std::string output;    // export: the file to write; empty: <session name>.<format> here
  bool json = false;
};

int sessions_list_command(const SessionsOptions& options, std::ostream& out, std::ostream& err);
int sessions_show_command(const SessionsOptions& options, std::ostream& out);
int sessions_export_command(const SessionsOptions& options, std::ostream& out);

}  // namespace bellows
