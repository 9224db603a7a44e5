#!/usr/bin/env bash
# A lab day in minutes: `bellows console --speed max --rt off` on the simulated arm runs 2000
# iterations of the paper trajectory (two batches of 1000), saving as it goes, and the console's
# resident memory (VmRSS) is read at iteration 10, 1000 and 2000. Bounded memory means the end
# is not far above the start. Results in docs/benchmarks.md ("Console soak").
# Usage: bench/console_soak.sh [path/to/bellows]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bellows="${1:-$root/build/app/bellows}"
command -v tmux >/dev/null || { echo "tmux missing: run scripts/setup.sh" >&2; exit 1; }
socket="bellows-soak-$$"
work="$(mktemp -d)"
trap 'tmux -L "$socket" kill-server 2>/dev/null || true; sleep 1; rm -rf "$work"' EXIT
export LC_ALL=C.UTF-8

tmux -L "$socket" new-session -d -s keep "sleep 100000"
tmux -L "$socket" new-session -d -s console -x 120 -y 40 \
  "exec env TERM=screen $bellows console --speed max --rt off --stop-after-rises 1000 --data-dir $work/sessions"
screen() { tmux -L "$socket" capture-pane -p -t console; }
wait_for() {  # REGEX [SECONDS]
  local deadline=$((SECONDS + ${2:-60}))
  while [ $SECONDS -lt "$deadline" ]; do grep -qE "$1" <<<"$(screen)" && return 0; sleep 0.2; done
  echo "timed out waiting for /$1/" >&2; screen >&2; exit 1
}
pid="$(tmux -L "$socket" display-message -p -t console '#{pane_pid}')"
rss_kib() { awk '/^VmRSS/ {print $2}' "/proc/$pid/status"; }
batch() {
  tmux -L "$socket" send-keys -t console N
  wait_for 'Run K'
  tmux -L "$socket" send-keys -t console BSpace BSpace 1000 Enter
}

wait_for 'law [a-z-]+  M'
tmux -L "$socket" send-keys -t console a
wait_for 'Arm the valves'
tmux -L "$socket" send-keys -t console y
wait_for 'Bellows +ARMED'
start=$SECONDS
batch
wait_for 'iteration 1[0-9] ' 120
rss_start=$(rss_kib)
wait_for 'iterations 0\.\.1000 done' 3600  # N 1000 from scratch: 0..1000 (docs/iterations.md)
rss_mid=$(rss_kib)
batch
wait_for 'iteration 2000 ' 3600
rss_end=$(rss_kib)
seconds=$((SECONDS - start))
sessions=$(ls "$work/sessions" | wc -l)
iterations=$(ls "$work"/sessions/*/iterations/ 2>/dev/null | grep -c "^iteration" || true)
tmux -L "$socket" send-keys -t console q
echo "2000 iterations in ${seconds} s; load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "VmRSS: at iteration ~10: ${rss_start} KiB; at 1000: ${rss_mid} KiB; at 2000: ${rss_end} KiB"
echo "sessions: ${sessions}, iteration files on disk: ${iterations}"
