#!/usr/bin/env bash
# The engine loop while the console redraws: runs `bellows console --speed 1 --rt try` in a detached
# tmux window (120x40) for a fixed time (--exit-after), arms, runs iterations the whole time (the
# screen redraws at its 30 Hz limit while trials run), resizes the window now and then, and prints
# the console's closing report: engine ticks, missed deadlines, wake-up latency, frames drawn and
# the UI thread's CPU share.
# Usage: bench/console_redraw.sh [seconds] [path/to/bellows]
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bellows="${2:-$root/build/app/bellows}"
command -v tmux >/dev/null || { echo "tmux missing: run scripts/setup.sh" >&2; exit 1; }
socket="bellows-bench-$$"
work="$(mktemp -d)"
trap 'tmux -L "$socket" kill-server 2>/dev/null || true; rm -rf "$work"' EXIT
export LC_ALL=C.UTF-8

tmux -L "$socket" new-session -d -s keep "sleep 100000"
tmux -L "$socket" set-option -g remain-on-exit on
tmux -L "$socket" new-session -d -s console -x 120 -y 40 \
  "exec env XDG_DATA_HOME=$work TERM=screen $bellows console --speed 1 --rt try --exit-after $seconds"
screen() { tmux -L "$socket" capture-pane -p -t console; }
wait_for() {
  for _ in $(seq 1 300); do grep -qE "$1" <<<"$(screen)" && return 0; sleep 0.2; done
  echo "timed out waiting for /$1/" >&2; screen >&2; exit 1
}
wait_for 'law [a-z-]+  M'
tmux -L "$socket" send-keys -t console a
wait_for 'Arm the valves'
tmux -L "$socket" send-keys -t console y
wait_for 'Bellows +ARMED'
tmux -L "$socket" send-keys -t console N
wait_for 'Run K'
tmux -L "$socket" send-keys -t console BSpace BSpace 1000 Enter
start=$SECONDS
while [ "$(tmux -L "$socket" display-message -p -t console '#{pane_dead}')" != "1" ]; do
  if [ $(( (SECONDS - start) % 10 )) -eq 5 ]; then  # a resize every 10 s: full redraws
    tmux -L "$socket" resize-window -t console -x 100 -y 30
    sleep 1
    tmux -L "$socket" resize-window -t console -x 120 -y 40
  fi
  sleep 1
done
tmux -L "$socket" capture-pane -p -J -S - -t console | grep -A1 '^bellows console:'
