#!/usr/bin/env bash
# The operator's day in the real binary: arm, choose `paper`, run iterations 0..5 (N 5) and read the falling
# RMS off the screen, inspect the correction and move the cursor, emergency stop and see FAULT,
# reset, re-arm, run again (saved as it goes), quit with the valves vented; relaunch with --session and see the
# same RMS history, find it in the browser, and continue learning into the same session.
source "$(dirname "$0")/e2e_console_lib.sh"

e2e_start 120 40 -- console --speed max --trajectory steps
e2e_wait_for 'Bellows +SAFE '
e2e_wait_law_ready

# Arm: asks first.
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '

# Choose paper (up from steps), with its preview.
e2e_keys t
e2e_wait_for 'steps  \(in use\)'
e2e_keys Up
e2e_wait_for 'paper: 8.0 s, 400 samples'
e2e_keys Enter
e2e_wait_for 'trajectory paper \(8.0 s\)'
e2e_wait_law_ready  # rebuilt for 400 samples

# Five learning iterations after the feedback-only one: 0..5, as `run --iterations 5` (docs/iterations.md).
e2e_keys N
e2e_wait_for 'Run K iterations'
e2e_keys BSpace BSpace 5 Enter
e2e_wait_for 'iterations 0\.\.5 done' 300
rms="$(e2e_rms_list)"
[ "$(echo "$rms" | awk '{print $1}' | tr '\n' ' ')" = "0 1 2 3 4 5 " ] || e2e_fail "RMS list: $rms"
e2e_expect_falling "$rms"
first="$(echo "$rms" | head -1 | awk '{print $2}')"
last="$(echo "$rms" | tail -1 | awk '{print $2}')"
awk -v a="$first" -v b="$last" 'BEGIN { exit !(a > 12 && b < a / 2) }' || e2e_fail "RMS from $first to $last"
e2e_wait_for "iteration 5  RMS $last deg"

# The correction inspector: the cursor moves along time and across iterations.
e2e_keys c
e2e_wait_for 'At the cursor'
e2e_wait_for 'Iteration 5 of 0\.\.5'
e2e_wait_for 'time +0\.00 s'
e2e_keys Right Right Right Right Right
e2e_wait_for 'time +0\.10 s'
e2e_wait_for 'sample +5 / 400'
e2e_keys PageDown
e2e_wait_for 'time +0\.90 s'
e2e_keys Up
e2e_wait_for 'Iteration 4 of 0\.\.5'
e2e_keys m
e2e_wait_for 'overlay: it 4'

# Emergency stop from the inspector: FAULT, the guard and the black box.
e2e_keys Space
e2e_wait_for 'FAULT: emergency-stop'
e2e_wait_for 'Last ticks before the fault'
e2e_wait_for 'Black box: last'
# Arming is refused while the fault is latched; reset, then arm again.
e2e_keys a
e2e_wait_for 'Arm: a fault is latched: reset it first'
e2e_keys R
e2e_wait_for 'Bellows +SAFE '
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '

# One more iteration after the fault: learning continues where it was.
e2e_keys n
e2e_wait_for 'iteration 6: RMS' 120
e2e_wait_for 'iteration 6  RMS'

# Saved as it went: quit does not ask; the closing report names the session, with every iteration.
for _ in $(seq 1 100); do e2e_screen_has 'unsaved' || break; sleep 0.1; done
history="$(e2e_rms_list)"
e2e_quit
status="$(e2e_wait_exit)"
[ "$status" = "0" ] || e2e_fail "exit status $status"
e2e_output_has 'bellows console: .* iterations 0\.\.6, best RMS .*valves vented'
e2e_output_has 'session: /.* \(saved as it went\)'
session="$(e2e_history | grep -oE '^session: /[^ ]+' | head -1 | cut -c10-)"
[ -f "$session/manifest.json" ] || e2e_fail "no session at '$session'"

# Relaunch on the saved session: the same RMS history, and learning goes on from it.
e2e_start 120 40 -- console --speed max --session "$session"
e2e_wait_for 'iteration 6  RMS'
e2e_wait_law_ready
[ "$(e2e_rms_list)" = "$history" ] || e2e_fail "RMS history after relaunch: $(e2e_rms_list | tr '\n' ' ') vs $(echo "$history" | tr '\n' ' ')"
# The browser lists it: date, trajectory, iterations, best RMS.
best="$(echo "$history" | awk 'NR == 1 || $2 < b { b = $2 } END { print b }')"
e2e_keys o
e2e_wait_for "> [0-9]{4}-[0-9]{2}-[0-9]{2} [0-9]{2}:[0-9]{2} +sim +paper +0\.\.6 +$best +$(basename "$session")"
e2e_keys Escape
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys n
e2e_wait_for 'iteration 7  RMS' 120
# Saved as it goes: the header drops "unsaved" once iteration 7 is on disk.
for _ in $(seq 1 100); do e2e_screen_has 'unsaved' || break; sleep 0.1; done
# Read whole before matching: `grep -q` would stop reading at the match and, under pipefail, the
# writer's SIGPIPE would fail the test.
shown="$("$BELLOWS" sessions show "$session")"
grep -qE '^iterations +0\.\.7,' <<<"$shown" || e2e_fail "the session did not grow to iterations 0..7: $shown"
e2e_quit
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status after the relaunch"
echo "ok: $(echo "$rms" | tr '\n' ' ')"
