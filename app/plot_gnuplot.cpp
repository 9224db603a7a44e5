#include "app/plot_gnuplot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "engine/base/errors.hpp"

extern char** environ;

namespace bellows {

void run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& directory) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0)
    throw EnvironmentError(std::string("cannot start gnuplot: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addchdir_np(&actions, directory.c_str());
  const std::string script_name = std::filesystem::absolute(script).string();
  char program[] = "gnuplot";
  char* argv[] = {program, const_cast<char*>(script_name.c_str()), nullptr};
  pid_t pid = -1;
  const int spawned = posix_spawnp(&pid, program, &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (spawned != 0) {
    ::close(pipe_fds[0]);
    if (spawned == ENOENT) throw EnvironmentError("gnuplot is not installed (Debian: apt-get install gnuplot-nox)");
    throw EnvironmentError(std::string("cannot start gnuplot: ") + std::strerror(spawned));
  }
  std::string output;
  char buffer[4096];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) != 0;) {
    if (n > 0) output.append(buffer, static_cast<std::size_t>(n));
    else if (errno != EINTR) break;
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    // gnuplot's message is its last non-empty line ("script.gp", line 12: ...).
    std::string line;
    std::size_t end = output.find_last_not_of("\n ");
    if (end != std::string::npos) {
      const std::size_t start = output.rfind('\n', end);
      line = output.substr(start == std::string::npos ? 0 : start + 1,
                           end - (start == std::string::npos ? 0 : start + 1) + 1);
    }
    throw InputError("gnuplot failed on " + script.string() + (line.empty() ? "" : ": " + line));
  }
}

}  // namespace bellows
