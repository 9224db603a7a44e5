#!/usr/bin/env bash
# The console saves as it goes: after 3 iterations on the simulated arm, `kill -9`, Ctrl-C and
# SIGHUP (the terminal closed: tmux kill-session) each leave a session on disk that `bellows
# sessions show` lists with iterations 0..2 and their RMS, and that `bellows run --resume`
# continues (iteration 3 next). Ctrl-C exits with 130, having vented and saved.
source "$(dirname "$0")/e2e_console_lib.sh"

data="$E2E_DIR/sessions"

# Until the pane's shell printed the exit status (e2e_wait_exit expects it to be there soon).
await_exit() {
  for _ in $(seq 1 300); do e2e_history_has -E '^EXIT STATUS [0-9]+' && break; sleep 0.2; done
  e2e_wait_exit
}

# Runs iterations 0..2 (N 2, docs/iterations.md) in a fresh console on its own data directory $1.
three_iterations() {
  e2e_start 120 40 -- console --speed max --rt off --data-dir "$1"
  e2e_wait_law_ready
  e2e_keys a
  e2e_wait_for 'Arm the valves\?'
  e2e_keys y
  e2e_wait_for 'Bellows +ARMED '
  e2e_keys N
  e2e_wait_for 'Run K'
  e2e_keys BSpace BSpace 2 Enter
  e2e_wait_for 'iterations 0\.\.2 done' 180
  # The header says "unsaved" from a trial's end until its autosave returned (milliseconds).
  for _ in $(seq 1 100); do e2e_screen_has 'unsaved' || return 0; sleep 0.1; done
  e2e_fail "the last iteration stayed unsaved"
}

# The one session in $1 lists iterations 0..2 with an RMS each, and a resumed run continues it.
expect_three_saved() {
  local dir="$1" how="$2" session show resumed
  session="$(ls -d "$dir"/*/ 2>/dev/null | head -1)"
  [ -n "$session" ] || e2e_fail "$how: no session saved in $dir"
  show="$("$BELLOWS" sessions show "$session" --data-dir "$dir" 2>&1)" || e2e_fail "$how: sessions show failed: $show"
  for i in 0 1 2; do
    grep -qE "^ *$i +[0-9]+\.[0-9]+" <<<"$show" || e2e_fail "$how: iteration $i missing from sessions show: $show"
  done
  grep -qE '^ *3 +[0-9]+\.[0-9]+' <<<"$show" && e2e_fail "$how: an iteration 3 that never ran: $show"
  resumed="$("$BELLOWS" run --resume "$session" --data-dir "$dir" --iterations 1 2>&1)" ||
    e2e_fail "$how: run --resume failed: $resumed"
  grep -qE '^iteration +3 ' <<<"$resumed" || e2e_fail "$how: the resumed run did not continue at iteration 3: $resumed"
}

# kill -9: nothing runs at exit, yet every completed iteration is on disk.
three_iterations "$data/kill9"
pid="$(e2e_pid)"
kill -KILL "$pid"
for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
expect_three_saved "$data/kill9" "kill -9"

# Ctrl-C: vent, save, restore the terminal, exit 130.
three_iterations "$data/ctrl-c"
e2e_keys C-c
status="$(await_exit)"
[ "$status" = "130" ] || e2e_fail "exit status after Ctrl-C: $status"
e2e_output_has 'valves vented'
e2e_output_has 'session: .*saved as it went'
expect_three_saved "$data/ctrl-c" "Ctrl-C"

# SIGHUP: the terminal goes away (tmux kills the session and its pane).
three_iterations "$data/hup"
pid="$(e2e_pid)"
e2e_tmux kill-session -t console
for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
kill -0 "$pid" 2>/dev/null && e2e_fail "the console outlived its terminal (SIGHUP)"
expect_three_saved "$data/hup" "SIGHUP"
echo ok
