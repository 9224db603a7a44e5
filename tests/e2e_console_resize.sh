#!/usr/bin/env bash
# Resizing at any moment: the window shrinks below 80x24 mid-run (a clear message, the trials go
# on), grows back, and the console draws every size without breaking; the run ends normally.
source "$(dirname "$0")/e2e_console_lib.sh"

e2e_start 120 40 -- console --speed 10
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys N
e2e_wait_for 'Run K iterations'
e2e_keys BSpace BSpace 2 Enter  # iterations 0..2 (docs/iterations.md)
e2e_wait_for 'batch +it 0\.\.2, 0 done'

e2e_resize 70 20
e2e_wait_for 'Terminal too small'
e2e_wait_for '70x20: Bellows needs at least 80x24'
e2e_resize 79 30
e2e_wait_for '79x30: Bellows needs at least 80x24'
e2e_resize 30 6
e2e_wait_for 'Terminal too small'
e2e_resize 80 24
e2e_wait_for 'RMS per iteration'
grep -q 'Space E-STOP' <<<"$(e2e_screen | tail -1)" || e2e_fail "no function bar at 80x24"
[ "$(e2e_screen | wc -l)" -eq 24 ] || e2e_fail "not 24 lines"
e2e_resize 100 30
e2e_wait_for 'Correction u_ilc'
e2e_resize 200 60
e2e_wait_for 'Live'
e2e_resize 120 40
e2e_wait_for 'iterations 0\.\.2 done' 300
rms="$(e2e_rms_list)"
[ "$(echo "$rms" | wc -l)" -eq 3 ] || e2e_fail "RMS list: $rms"
e2e_expect_falling "$rms"
e2e_screen_has 'FAULT' && e2e_fail "a fault during the resizes"
e2e_keys l
e2e_wait_for 'Event log'
e2e_screen_has 'refused' && e2e_fail "a command was refused"
e2e_quit  # saved as it went; armed, so quitting asks (docs/console.md, "Quit")
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
echo "ok: $(echo "$rms" | tr '\n' ' ')"
