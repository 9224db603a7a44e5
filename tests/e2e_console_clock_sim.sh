#!/usr/bin/env bash
# Issue 23, reproducible numbers: `bellows console --clock sim --speed max`, arm, N 5, quit; the
# session reopened in the console with --clock sim, arm (where it stopped: the engine, the arm and
# the clock as `run --resume` puts them), N 5 more: the session holds exactly the RMS values of
# `bellows run --iterations 10 --json` with the same seed (to the last digit: the JSON's shortest
# round-trip numbers compared as text), and the header says which clock runs. Every saved
# iteration after the first records the law and weights it was learned with (learned_with).
source "$(dirname "$0")/e2e_console_lib.sh"

seed=7
# arm_and_run_5 SPAN: arm, N 5, until "iterations SPAN done".
arm_and_run_5() {
  e2e_wait_law_ready
  e2e_arm
  e2e_keys N
  e2e_wait_for 'Run K iterations'
  e2e_keys BSpace BSpace BSpace 5 Enter
  e2e_wait_for "iterations $1 done" 600
}
e2e_start 120 40 -- console --clock sim --speed max --seed "$seed"
e2e_wait_for 'Bellows +SAFE '
e2e_wait_for 'sim clock'
e2e_wait_for 'a arms the valves'
arm_and_run_5 '0\.\.5'
e2e_keys d
e2e_wait_for 'Bellows +SAFE '
e2e_quit
[ "$(e2e_wait_exit)" = 0 ] || e2e_fail "the console did not exit cleanly"
e2e_output_has 'simulated clock'
session="$(find "$E2E_DIR/data/bellows/sessions" -mindepth 1 -maxdepth 1 -type d)"
[ -d "$session" ] || e2e_fail "expected one saved session, found: $session"

# Reopened: the first arm continues where the session stopped.
e2e_start 120 40 -- console --clock sim --speed max --session "$session"
e2e_wait_for 'sim clock'
e2e_wait_for 'a arms the valves'
arm_and_run_5 '6\.\.10'
e2e_keys d
e2e_wait_for 'Bellows +SAFE '
e2e_quit
[ "$(e2e_wait_exit)" = 0 ] || e2e_fail "the reopened console did not exit cleanly"
grep -q 'arm where the session stopped' "$session/manifest.json" || e2e_fail "the reopened session was armed afresh"

sessions=("$E2E_DIR"/data/bellows/sessions/*/manifest.json)
[ "${#sessions[@]}" = 1 ] && [ -f "${sessions[0]}" ] || e2e_fail "expected one saved session, found: ${sessions[*]}"
"$BELLOWS" run --iterations 10 --json --quiet --seed "$seed" --data-dir "$E2E_DIR/run" >"$E2E_DIR/run.json" ||
  e2e_fail "bellows run failed"

python3 - "${sessions[0]}" "$E2E_DIR/run.json" <<'PY' || e2e_fail "the console's RMS values are not run's"
import json, sys
manifest = json.load(open(sys.argv[1]))
run = json.load(open(sys.argv[2]))
console_rms = [repr(i["rms_deg"]) for i in manifest["iterations"]]
run_rms = [repr(i["rms_deg"]) for i in run["iterations"]]
print("console:", " ".join(console_rms))
print("run:    ", " ".join(run_rms))
assert len(console_rms) == 11, len(console_rms)
assert console_rms == run_rms, "different"
learned = [i.get("learned_with") for i in manifest["iterations"]]
assert learned[0] is None, learned[0]
assert all(l is not None and l["law"] == "noilc" and set(l) == {"law", "m", "s", "w"} for l in learned[1:]), learned
PY
echo "PASS: console --clock sim gives run's RMS values"
