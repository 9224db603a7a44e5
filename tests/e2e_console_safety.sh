#!/usr/bin/env bash
# The console's safety duties in the real binary: when it stops sending heartbeats (the drill
# withholds them) the engine vents by itself; SIGTERM vents and exits with 128 + 15.
source "$(dirname "$0")/e2e_console_lib.sh"

e2e_start 120 40 -- console --speed 2  # (at x1 a loaded machine could trip the missed-deadline guard)
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
sleep 2  # armed for a while: the heartbeat keeps it so
e2e_screen_has -E 'Bellows +ARMED ' || e2e_fail "the armed engine did not stay armed"
e2e_keys H
e2e_wait_for 'FAULT: heartbeat-lost' 30
e2e_wait_for 'the console stopped responding'
e2e_keys l
e2e_wait_for 'heartbeat drill: the engine vented after [0-9.]+ s without heartbeat'

# Reset, arm, then SIGTERM: vent and exit 143 with the closing summary.
e2e_keys R
e2e_wait_for 'Bellows +SAFE '
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
kill -TERM "$(e2e_pid)"
status="$(e2e_wait_exit)"
[ "$status" = "143" ] || e2e_fail "exit status after SIGTERM: $status ($(e2e_tmux display-message -p -t console "signal #{pane_dead_signal}"))"
e2e_output_has 'valves vented'
echo ok
