# Driving the real bellows binary inside tmux, for the console's end-to-end tests. Sourced by
# tests/e2e_console_*.sh with the binary as $1. Each test gets its own tmux server (-L) and its own
# data directory; the pane stays after the program exits so its exit status and last screen can
# be read. Waits poll the screen with generous limits: these tests run on loaded 2-core machines.
set -euo pipefail

BELLOWS="${1:?usage: $0 path/to/bellows}"
command -v tmux >/dev/null || { echo "tmux is not installed (scripts/setup.sh installs it)"; exit 1; }
E2E_NAME="$(basename "$0" .sh)"
E2E_SOCKET="bellows-${E2E_NAME}-$$"
E2E_DIR="$(mktemp -d "${TMPDIR:-/tmp}/${E2E_NAME}-XXXXXX")"
E2E_WAIT_S="${E2E_WAIT_S:-90}"
export LC_ALL=C.UTF-8  # tmux's own client (capture-pane) reads and writes UTF-8
unset TMUX             # the tests may run inside a tmux session themselves

e2e_tmux() { tmux -L "$E2E_SOCKET" "$@"; }

e2e_cleanup() {
  e2e_tmux kill-server 2>/dev/null || true
  rm -rf "$E2E_DIR"
}
trap e2e_cleanup EXIT

e2e_fail() {
  echo "FAIL ($E2E_NAME): $*" >&2
  echo "---- screen ----" >&2
  e2e_screen >&2 || true
  echo "---- pane ----" >&2
  local pid
  pid="$(e2e_pid 2>/dev/null || true)"
  [ -n "$pid" ] && grep -E '^(Name|State)' "/proc/$pid/status" >&2 || echo "no bellows process" >&2
  exit 1
}

# e2e_start WIDTH HEIGHT [ENV=VALUE...] -- ARGS...: starts `bellows ARGS` in a WIDTHxHEIGHT window.
# A shell in the pane runs it in the foreground, reaps it and prints "EXIT STATUS n" after it (tmux
# 3.3a does not always reap a pane's process, so its #{pane_dead_status} cannot be relied on).
e2e_start() {
  local width="$1" height="$2"
  shift 2
  local env=("XDG_DATA_HOME=$E2E_DIR/data" "LC_ALL=C.UTF-8" "TERM=screen")
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do env+=("$1"); shift; done
  [ "${1:-}" = "--" ] && shift
  local program="env"
  for e in "${env[@]}"; do program+=" $(printf '%q' "$e")"; done
  program+=" $(printf '%q' "$BELLOWS")"
  for a in "$@"; do program+=" $(printf '%q' "$a")"; done
  if ! e2e_tmux has-session -t keep 2>/dev/null; then
    e2e_tmux new-session -d -s keep -x 80 -y 24 "sleep 100000"
  fi
  e2e_tmux kill-session -t console 2>/dev/null || true
  e2e_tmux new-session -d -s console -x "$width" -y "$height" \
    "$program; echo \"EXIT STATUS \$?\"; exec sleep 100000"
}

# e2e_keys KEYS...: tmux send-keys. An Escape goes alone and is followed by a pause longer than the
# console's escape delay: Esc with a key right behind it is one Alt+key to the console (ui/terminal.cpp).
e2e_keys() {
  if [ "${1:-}" != -l ] && [[ " $* " == *" Escape "* ]]; then
    local k
    for k in "$@"; do
      e2e_tmux send-keys -t console "$k"
      if [ "$k" = Escape ]; then sleep 0.1; fi
    done
    return 0
  fi
  e2e_tmux send-keys -t console "$@"
}
e2e_screen() { e2e_tmux capture-pane -p -t console; }
e2e_history() { e2e_tmux capture-pane -p -J -S - -t console; }  # the screen and what scrolled off it
# e2e_screen_has [GREP OPTIONS] PATTERN, e2e_history_has ...: grep -q on the whole capture. Never
# `e2e_screen | grep -q`: grep leaves at the first match, the capture still being written gets
# SIGPIPE, and under pipefail the match reads as a failure (scripts/house-style.sh refuses it).
e2e_screen_has() { local text; text="$(e2e_screen)"; grep -q "$@" <<<"$text"; }
e2e_history_has() { local text; text="$(e2e_history)"; grep -q "$@" <<<"$text"; }
e2e_resize() { e2e_tmux resize-window -t console -x "$1" -y "$2"; }

# e2e_wait_for REGEX [SECONDS]: until the screen matches (grep -E).
e2e_wait_for() {
  local pattern="$1" limit="${2:-$E2E_WAIT_S}"
  local deadline=$((SECONDS + limit))
  while [ $SECONDS -lt $deadline ]; do
    if e2e_screen_has -E -- "$pattern"; then return 0; fi
    if e2e_history_has -E '^EXIT STATUS [0-9]+'; then
      e2e_screen_has -E -- "$pattern" && return 0
      e2e_fail "the console exited while waiting for /$pattern/"
    fi
    sleep 0.2
  done
  e2e_fail "no /$pattern/ on the screen within ${limit} s"
}

# e2e_wait_gone REGEX [SECONDS]: until the screen no longer matches (a dialog closed): the frame
# after a key comes within the console's redraw interval, not at once.
e2e_wait_gone() {
  local pattern="$1" limit="${2:-$E2E_WAIT_S}"
  local deadline=$((SECONDS + limit))
  while [ $SECONDS -lt $deadline ]; do
    e2e_screen_has -E -- "$pattern" || return 0
    sleep 0.2
  done
  e2e_fail "/$pattern/ still on the screen after ${limit} s"
}

# e2e_output_has REGEX: the program's output (screen and history) matches, e.g. after it exited.
e2e_output_has() { e2e_history_has -E -- "$1" || e2e_fail "no /$1/ in the output"; }

# e2e_wait_exit [SECONDS]: until the program exited; prints its exit status.
e2e_wait_exit() {
  local limit="${1:-$E2E_WAIT_S}"
  local deadline=$((SECONDS + limit))
  while [ $SECONDS -lt $deadline ]; do
    local line
    # `|| true`: before the status is printed grep finds nothing, which under pipefail and set -e
    # would end the script silently instead of waiting.
    line="$(e2e_history | grep -oE '^EXIT STATUS [0-9]+' | tail -1 || true)"
    if [ -n "$line" ]; then
      echo "${line#EXIT STATUS }"
      return 0
    fi
    sleep 0.2
  done
  e2e_fail "the console did not exit within ${limit} s"
}

# The bellows process: the child of the pane's shell (env execs it).
e2e_pid() {
  local shell
  shell="$(e2e_tmux display-message -p -t console '#{pane_pid}')"
  awk '{print $1; exit}' "/proc/$shell/task/$shell/children"
}

# The RMS list of the main screen as "iteration rms" lines.
e2e_rms_list() {
  # A row ends in its value, then the best's `*` or a space, then the panel's frame.
  e2e_screen | grep -oE ' [0-9]+ +[0-9]+\.[0-9]{3}[* ]?[│|]' | sed -E 's/[*│|]//g; s/^ +//; s/ +$//; s/ +/ /'
}

# e2e_expect_falling LIST: each RMS below the one before.
e2e_expect_falling() {
  echo "$1" | awk 'NR > 1 && $2 >= previous { bad = 1 } { previous = $2 } END { exit bad }' ||
    e2e_fail "RMS not falling: $(echo "$1" | tr '\n' ' ')"
}

# e2e_wait_law_ready [LIMIT_S]: the header shows the learning law ready (its weights, not
# "(preparing)"): `N` before that is refused (a reopened session's law is prepared again too).
e2e_wait_law_ready() {
  e2e_wait_for 'law [a-z-]+  M' "$@"
}

# e2e_arm: `a`, then `y` to the question: the valves ARMED.
e2e_arm() {
  e2e_keys a
  e2e_wait_for 'Arm the valves\?'
  e2e_keys y
  e2e_wait_for 'Bellows +ARMED '
}

# e2e_quit: `q`, and `y` when the console asks (it does while the valves are live, or when work
# would be lost: docs/console.md, "Quit").
e2e_quit() {
  e2e_keys q
  local deadline=$((SECONDS + 10))
  while [ $SECONDS -lt $deadline ]; do
    if e2e_history_has -E '^EXIT STATUS [0-9]+'; then return 0; fi
    if e2e_screen_has 'Quit?'; then e2e_keys y; return 0; fi
    sleep 0.1
  done
}
