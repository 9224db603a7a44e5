#!/usr/bin/env bash
# Issue 23 in the real binary, one console walking every prompt and question it has (ui/console_keys.cpp
# DialogKind; tests/test_ui_prompts.cpp checks the same in process): each gets a refused answer,
# then a string full of command letters, then Esc. The prompt shows what was typed and why it was
# refused; afterwards no trial ran, the valves are still ARMED (SAFE for the questions asked before
# arming), and the session on disk is byte for byte what it was. A good name then renames the
# session: `sessions show` and `sessions list` print it. Last, a save that fails leaves work unsaved,
# which is when the discard and quit questions appear: they take only their answers too.
source "$(dirname "$0")/e2e_console_lib.sh"

# Every command key but Space (the emergency stop, which works in prompts too).
letters='brdnNaxtcwlsofgHjTRqv?zmuyYe'
# The letters without a question's own answers (y/n/q and, for quitting, c and s too).
question_letters="$(tr -d 'yYnNq' <<<"$letters")"
quit_letters="$(tr -d 'yYnNqcs' <<<"$letters")"

# has_text TEXT: the screen shows TEXT (fixed string).
has_text() { e2e_screen_has -F -- "$1"; }
# wait_text TEXT / wait_gone TEXT: until the screen shows TEXT (a fixed string) / no longer does.
wait_text() { wait_screen_text shown "$1"; }
wait_gone() { wait_screen_text gone "$1"; }
wait_screen_text() {
  local want="$1" text="$2" deadline=$((SECONDS + E2E_WAIT_S)) now
  while true; do
    now=gone
    has_text "$text" && now=shown
    [ "$now" = "$want" ] && return 0
    [ $SECONDS -lt $deadline ] || e2e_fail "'$text' not $want on the screen within ${E2E_WAIT_S} s"
    sleep 0.1
  done
}
session_dir() { find "$E2E_DIR/data/bellows/sessions" -mindepth 1 -maxdepth 1 -type d | head -1; }
session_digest() { (cd "$(session_dir)" && find . -type f ! -name '*.lock' -print0 | sort -z | xargs -0 sha256sum); }

# prompt TITLE REFUSED WHY: the prompt TITLE is open; Ctrl-U, REFUSED, Enter: refused (WHY shown,
# the text kept); the letters then stay text in the field; Esc closes it.
prompt() {
  local title="$1" refused="$2" why="$3"
  wait_text "$title"
  # WHY must be new on the screen, or waiting for it would not wait for the refusal at all.
  has_text "$why" && e2e_fail "$title: '$why' is on the screen before the answer was given"
  e2e_keys C-u
  e2e_keys -l -- "$refused"
  e2e_keys Enter
  wait_text "$why"
  local shown="$refused"
  [ ${#shown} -le 30 ] || shown="${shown: -30}"  # a long answer: the field shows its end
  has_text "$shown" || e2e_fail "$title: the refused answer '$refused' is not shown"
  e2e_keys -l -- "$letters"
  wait_text "${letters: -20}_"  # the field's end: the last letters typed, then its cursor
  has_text "$title" || e2e_fail "$title: the prompt closed while letters were typed"
  # Alt+letters arrive as Esc and the letter at once: one key that does nothing, not an Esc that
  # closes the prompt and then a command (Alt-r ran a trial, Alt-d disarmed).
  e2e_keys M-r M-n M-d
  wait_text "this key does nothing here"
  has_text "$title" || e2e_fail "$title: an Alt+letter closed the prompt"
  e2e_keys Escape
  wait_gone "$title"
}

# question TITLE LETTERS STATE: the question TITLE is open; every key of LETTERS is named as not an
# answer and the question stays; Esc closes it; the engine is still in STATE.
question() {
  local title="$1" keys="$2" state="$3"
  wait_text "$title"
  has_text "${keys: -1} is not an answer here" && e2e_fail "$title: refused before a key was typed"
  e2e_keys -l -- "$keys"
  wait_text "${keys: -1} is not an answer here"
  has_text "$title" || e2e_fail "$title: a letter closed the question"
  e2e_keys Escape
  wait_gone "$title"
  e2e_wait_for "Bellows +$state "
}

e2e_start 120 40 -- console --speed max --rt off
e2e_wait_law_ready

# Before arming: the arm question and the valve test's (Rig screen, v).
e2e_keys a
question 'Arm the valves?' "$question_letters" SAFE
e2e_keys b
e2e_wait_for 'Valve test \(v starts it'
e2e_keys v
question 'Valve test: open each valve alone?' "$question_letters" SAFE
e2e_keys Escape

# One trial, saved: the session every later prompt must leave alone.
e2e_arm
e2e_keys r
e2e_wait_for 'iteration 0  RMS' 120
for _ in $(seq 1 100); do has_text 'unsaved' || break; sleep 0.1; done
[ -n "$(session_dir)" ] || e2e_fail "the first trial was not saved"
before="$(session_digest)"
rms_before="$(e2e_rms_list)"
[ "$(wc -l <<<"$rms_before")" = 1 ] || e2e_fail "expected one iteration, found: $rms_before"

# K (N).
e2e_keys N
prompt 'Run K iterations' '2.5' 'K must be a whole number'
e2e_keys N
prompt 'Run K iterations' "$(printf '7%.0s' $(seq 1 400))" '(out of range)'

# Every gain and weight of the tuning screen (w; rows k_ff k_p k_i k_d, the law, M S W).
e2e_keys w
e2e_wait_for 'k_ff'
refusals=('０.５' 'abc' "1$(printf '0%.0s' $(seq 1 399))" '20' '' '-1' 'nan' '2e6')
# Each why names the field and the answer: the field's label alone is on the screen already.
whys=("k_ff: '" "k_p: 'abc' is not a number" "' is out of range" '[controller] k_d = 20: must be in' ''
  '[ilc] m = -1: must be in' "S: 'nan' is not a number" '[ilc] w = 2000000: must be in')
labels=(k_ff k_p k_i k_d law M S W)
for row in 0 1 2 3 5 6 7; do
  for _ in $(seq 0 7); do e2e_keys Up; done
  for _ in $(seq 1 "$row"); do e2e_keys Down; done
  e2e_keys Enter
  prompt "Change ${labels[$row]}" "${refusals[$row]}" "${whys[$row]}"
done
e2e_keys Escape

# The trajectory's CSV path (t, the file entry, Enter).
e2e_keys t
e2e_wait_for 'from a file'
for _ in $(seq 1 20); do e2e_keys Down; done
e2e_keys Enter
prompt 'Trajectory file' '/nonexistent.csv' 'cannot be read'
has_text 'Trajectory chooser' || e2e_wait_for 'from a file'  # back on the chooser
e2e_keys Escape

# The session's name (s).
e2e_keys s
prompt 'Name this session' '../escape' "session name '../escape' must"

# Quitting while ARMED asks (its answers: q y quit, n c stay, s save).
e2e_keys q
question 'Quit?' "$quit_letters" ARMED

# Nothing happened: the valves ARMED, one iteration, the session as it was.
sleep 0.5  # a trial started by a stray key would be running by now
e2e_wait_for 'Bellows +ARMED '
[ "$(e2e_rms_list)" = "$rms_before" ] || e2e_fail "the iterations changed: $(e2e_rms_list | tr '\n' ' ')"
[ "$(session_digest)" = "$before" ] || e2e_fail "the session on disk changed"
[ -d "$E2E_DIR/data/bellows/sessions/escape" ] && e2e_fail "a session escaped"

# A good name renames it.
e2e_keys s
wait_text 'Name this session'
e2e_keys C-u
e2e_keys -l 'bench-a'
e2e_keys Enter
e2e_wait_for 'named: .*bench-a'
shown="$(XDG_DATA_HOME="$E2E_DIR/data" "$BELLOWS" sessions show bench-a)"
grep -qE '^name +bench-a' <<<"$shown" || e2e_fail "sessions show does not name it bench-a: $shown"
listed="$(XDG_DATA_HOME="$E2E_DIR/data" "$BELLOWS" sessions list)"
grep -q 'bench-a' <<<"$listed" || e2e_fail "sessions list: $listed"

# A save that fails leaves the next trial unsaved; choosing a trajectory then asks to discard it,
# quitting offers to save. The session's folder is made unwritable: immutable (chattr +i, which
# binds root too), or without write permission when not run as root.
locked="$E2E_DIR/data/bellows/sessions/bench-a"
unlock() { chattr -i "$locked" 2>/dev/null || true; chmod u+w "$locked" 2>/dev/null || true; }
trap 'unlock; e2e_cleanup' EXIT
chattr +i "$locked" 2>/dev/null || chmod a-w "$locked"
if touch "$locked/probe" 2>/dev/null; then
  e2e_fail "cannot make $locked unwritable (chattr +i needs CAP_LINUX_IMMUTABLE when run as root)"
fi
e2e_keys r
e2e_wait_for 'iteration 1  RMS|not saved|save failed' 120
wait_text 'unsaved'
e2e_keys t
e2e_wait_for 'from a file'
e2e_keys Down Enter
question 'Discard unsaved work?' "$question_letters" ARMED
e2e_keys Escape
e2e_keys q
question 'Quit?' "$quit_letters" ARMED
e2e_keys q
wait_text 'Quit?'
e2e_keys q  # quit without saving: the console says what it did not save, with its own exit status
[ "$(e2e_wait_exit)" = "4" ] || e2e_fail "exit status (4: work not saved)"
e2e_output_has 'not saved: iteration 1 is not saved'
unlock
iterations="$(XDG_DATA_HOME="$E2E_DIR/data" "$BELLOWS" sessions show bench-a --json |
  python3 -c 'import json, sys; print(len(json.load(sys.stdin)["iterations"]))')"
[ "$iterations" = 1 ] || e2e_fail "bench-a holds $iterations iterations, expected the one saved"
echo ok
