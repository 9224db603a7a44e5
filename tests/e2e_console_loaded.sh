#!/usr/bin/env bash
# The console on the simulated arm on a loaded machine: both cores busy (two `yes`, started and
# stopped here) and the console stopped outright for a moment mid-trial (SIGSTOP/SIGCONT: deadlines
# are certainly missed). The simulated arm's time follows the engine's ticks, so the missed
# deadlines are counted and logged as a warning, never a fault: 3 iterations complete.
source "$(dirname "$0")/e2e_console_lib.sh"

loads=()
stop_loads() { for p in "${loads[@]}"; do kill "$p" 2>/dev/null || true; done; }
trap 'stop_loads; e2e_cleanup' EXIT
yes >/dev/null & loads+=($!)
yes >/dev/null & loads+=($!)

e2e_start 120 40 -- console --speed 1 --rt off --data-dir "$E2E_DIR/sessions"
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys N
e2e_wait_for 'Run K'
e2e_keys BSpace BSpace 2 Enter  # iterations 0..2 (docs/iterations.md)
e2e_wait_for 'Bellows +RUNNING ' 60
sleep 2
pid="$(e2e_pid)"
kill -STOP "$pid"
sleep 0.3
kill -CONT "$pid"
e2e_wait_for 'iterations 0\.\.2 done' 240
e2e_screen_has 'FAULT' && e2e_fail "a fault on the simulated arm under load"
missed="$(e2e_screen | grep -oE 'missed [0-9]+' | head -1 | grep -oE '[0-9]+')"
[ "${missed:-0}" -gt 0 ] || e2e_fail "no missed deadline counted after a 0.3 s stall"
stop_loads
e2e_quit
status="$(e2e_wait_exit)"
[ "$status" = "0" ] || e2e_fail "exit status $status"
e2e_output_has '[0-9]+ deadlines missed, counted as warnings'
e2e_history_has -E 'iterations' || true
echo "ok (missed deadlines counted: $missed)"
