#!/usr/bin/env bash
# At 80x24 (the smallest console) the real binary keeps the function bar's E-STOP, help and quit,
# its help lists every key of every screen (T and the Rig screen's v included) when scrolled with
# PgDn, greyed keys keep their reason, the tuning screen says how to edit a value, and after an
# emergency stop the live panel shows no set point and no tracking error.
source "$(dirname "$0")/e2e_console_lib.sh"

e2e_start 80 24 LC_ALL=C LANG=C -- console --speed max --rt off
e2e_wait_for 'law [a-z-]+'
grep -qF '?/F1 Help' <<<"$(e2e_screen | tail -n 1)" || e2e_fail "no help key in the function bar at 80 columns"
grep -qF 'q Quit' <<<"$(e2e_screen | tail -n 1)" || e2e_fail "no quit key in the function bar at 80 columns"
e2e_keys '?'
e2e_wait_for 'Everywhere \(greyed'
e2e_wait_for '\(arm the valves first \(a\)\)'
help=""
for _ in 1 2 3 4 5 6; do
  help+="$(e2e_screen)"$'\n'
  e2e_keys NPage
  sleep 0.3
done
for key in 'Space ' 'Esc ' ' T ' 'Left/Right' ' v ' ' u ' ' m ' 'close the help'; do
  grep -qF -- "$key" <<<"$help" || e2e_fail "help at 80x24 lacks '$key'"
done
grep -qF 'Rig screen (b)' <<<"$help" || e2e_fail "help lacks the Rig screen's keys"
grep -qF 'Session browser (o)' <<<"$help" || e2e_fail "help lacks the browser's keys"
e2e_keys Escape w
e2e_wait_for 'Enter edit: type the value, Enter applies, Esc cancels'
e2e_keys Escape a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r
sleep 1
e2e_keys Space
e2e_wait_for 'FAULT'
e2e_keys Escape
e2e_wait_for 'set point  none: vented'
e2e_wait_for 'error      no trial'
e2e_keys R
e2e_quit
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
echo "PASS"
