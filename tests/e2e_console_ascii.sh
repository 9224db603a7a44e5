#!/usr/bin/env bash
# Without a UTF-8 locale the console draws ASCII only (plots with marks instead of braille); with
# --no-color (or NO_COLOR), or on a terminal without colours (TERM=vt100), it uses attributes
# alone. A trial runs and its RMS shows as before.
source "$(dirname "$0")/e2e_console_lib.sh"

# has_reverse_video: within E2E_WAIT_S the escaped screen shows reverse video (SGR 7). A capture taken
# while the console repaints (after a dialog closes) can catch the screen between its cells and their
# attributes, so one capture is not enough.
has_reverse_video() {
  local deadline=$((SECONDS + E2E_WAIT_S))
  while [ $SECONDS -lt $deadline ]; do
    escaped="$(e2e_tmux capture-pane -p -e -t console)"
    grep -qE $'\e\\[([0-9]+;)*7(;[0-9]+)*m' <<<"$escaped" && return 0
    sleep 0.1
  done
  return 1
}

e2e_start 100 30 LC_ALL=C LANG=C -- console --speed max --no-color
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r
e2e_wait_for 'iteration 0  RMS [0-9]+\.[0-9]{3} deg' 120  # the header names the iteration run
e2e_wait_for 'Iteration 0: angle and set point'
e2e_screen_has -F '+- Live ---' || e2e_fail "no ASCII frame"
e2e_screen_has -E '\|[^|]*\*\*' || e2e_fail "no ASCII plot marks"
non_ascii="$(e2e_screen | LC_ALL=C tr -d '\000-\177' | wc -c)"
[ "$non_ascii" -eq 0 ] || e2e_fail "$non_ascii non-ASCII bytes on an ASCII screen"
# No colour escape (foreground 30-37, background 40-47), but attributes (reverse video) remain.
escaped="$(e2e_tmux capture-pane -p -e -t console)"
grep -qE $'\e\\[([0-9]+;)*(3[0-7]|4[0-7])(;[0-9]+)*m' <<<"$escaped" && e2e_fail "colours with --no-color"
has_reverse_video || e2e_fail "no reverse video for the keys and states"

# A terminal without colours (vt100), without --no-color: attributes alone, and it still works.
e2e_quit  # saved as it went; armed, so quitting asks (docs/console.md, "Quit")
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
e2e_start 100 30 TERM=vt100 -- console --speed max
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r
e2e_wait_for 'iteration 0  RMS [0-9]+\.[0-9]{3} deg' 120  # the header names the iteration run
escaped="$(e2e_tmux capture-pane -p -e -t console)"
grep -qE $'\e\\[([0-9]+;)*(3[0-7]|4[0-7])(;[0-9]+)*m' <<<"$escaped" && e2e_fail "colours on a vt100"
has_reverse_video || e2e_fail "no reverse video on a vt100"

# The same screen in a UTF-8 locale with colours: braille and colour escapes.
e2e_quit  # saved as it went; armed, so quitting asks (docs/console.md, "Quit")
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
e2e_start 100 30 -- console --speed max
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r
e2e_wait_for 'Iteration 0: angle and set point' 120
screen="$(e2e_screen)"
LC_ALL=C grep -q $'\xe2[\xa0-\xa3]' <<<"$screen" || e2e_fail "no braille in a UTF-8 locale"  # U+2800..U+28FF
escaped="$(e2e_tmux capture-pane -p -e -t console)"
grep -qE $'\e\\[([0-9]+;)*(3[0-7]|4[0-7])(;[0-9]+)*m' <<<"$escaped" || e2e_fail "no colours"
e2e_quit  # saved as it went; armed, so quitting asks (docs/console.md, "Quit")
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status"
echo ok
