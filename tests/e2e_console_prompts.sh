#!/usr/bin/env bash
# Issue 23 in the real binary: keys typed into a prompt never run commands. A refused CSV path and a
# refused session name keep their prompt open with what was typed and why, and the command letters
# typed next (b r d n, a second path) stay text: the valves stay ARMED and no trial runs. A good
# name then renames the session: `sessions show` and `sessions list` print it.
source "$(dirname "$0")/e2e_console_lib.sh"

e2e_start 120 40 -- console --speed max --rt off
e2e_wait_for 'law [a-z-]+  M'
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '

# The trajectory's CSV-path prompt (t, the file entry, Enter).
e2e_keys t
e2e_wait_for 'from a file'
for _ in $(seq 1 20); do e2e_keys Down; done
e2e_keys Enter
e2e_wait_for 'Trajectory file'
e2e_keys C-u
e2e_keys -l '/nonexistent.csv'
e2e_keys Enter
e2e_wait_for 'cannot be read'
e2e_keys -l '/home/lab/run.csv'  # b (Rig) and r (run) among the letters
e2e_wait_for 'nonexistent\.csv/home/lab/run\.csv'
e2e_keys -l 'brdn'
e2e_wait_for 'run\.csvbrdn'
e2e_screen | grep -qE 'Bellows +ARMED ' || e2e_fail "the valves are not ARMED after typing into the path prompt"
e2e_screen | grep -q 'Trajectory file' || e2e_fail "the path prompt closed"
e2e_keys Escape Escape
e2e_wait_for 'iteration -'  # no trial ran

# One trial: a session to name.
e2e_keys r
e2e_wait_for 'iteration 0  RMS' 120
for _ in $(seq 1 100); do e2e_screen | grep -q 'unsaved' || break; sleep 0.1; done

# The name prompt (s): a refused name keeps it, checked before it closes.
e2e_keys s
e2e_wait_for 'Name this session'
e2e_keys C-u
e2e_keys -l '../escape'
e2e_keys Enter
e2e_wait_for "session name '\.\./escape' must"
e2e_keys -l 'dnr'
e2e_wait_for '\.\./escapednr'
e2e_screen | grep -q 'Name this session' || e2e_fail "the name prompt closed"
sleep 0.5
e2e_screen | grep -qE 'Bellows +ARMED .*iteration 0  RMS' || e2e_fail "a key typed into the name prompt acted"
e2e_keys Escape
e2e_keys s
e2e_wait_for 'Name this session'
e2e_keys C-u
e2e_keys -l 'bench-a'
e2e_keys Enter
e2e_wait_for 'named: .*bench-a'
e2e_quit
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
[ -d "$E2E_DIR/data/bellows/sessions/escape" ] && e2e_fail "a session escaped"
shown="$(XDG_DATA_HOME="$E2E_DIR/data" "$BELLOWS" sessions show bench-a)"
grep -qE '^name +bench-a' <<<"$shown" || e2e_fail "sessions show does not name it bench-a: $shown"
listed="$(XDG_DATA_HOME="$E2E_DIR/data" "$BELLOWS" sessions list)"
grep -q 'bench-a' <<<"$listed" || e2e_fail "sessions list: $listed"
echo ok
