// `bellows completion bash`: the bash completion script, generated from the command line's own
// tree (subcommands, options, the values an option accepts) so that it cannot go stale. The build
// writes it into share/bash-completion/completions/bellows and installs it (CMakeLists.txt).
#pragma once

#include <string>

namespace CLI {
class App;
}

namespace bellows {

/// The bash completion script for `app` (hidden subcommands, those without a group, left out).
std::string bash_completion(const CLI::App& app);

}  // namespace bellows
