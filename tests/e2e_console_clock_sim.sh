#!/usr/bin/env bash
# Issue 23, reproducible numbers: `bellows console --clock sim --speed max`, arm, N 10: the session the
# console saved holds exactly the RMS values of `bellows run --iterations 10 --json` with the same
# seed (to the last digit: the JSON's shortest round-trip numbers compared as text), and the header
# says which clock runs. Every saved iteration after the first records the law and weights it was
# learned with (the manifest's learned_with).
source "$(dirname "$0")/e2e_console_lib.sh"

seed=7
e2e_start 120 40 -- console --clock sim --speed max --seed "$seed"
e2e_wait_for 'Bellows +SAFE '
e2e_wait_for 'sim clock'
e2e_wait_for 'law [a-z-]+'  # the header names the law once it is ready
e2e_wait_for 'a arms the valves'
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys N
e2e_wait_for 'Run K iterations'
e2e_keys BSpace BSpace BSpace 10 Enter
e2e_wait_for 'iterations 0\.\.10 done' 600
e2e_keys d
e2e_wait_for 'Bellows +SAFE '
e2e_keys q
sleep 1
if ! e2e_history | grep -qE '^EXIT STATUS'; then e2e_screen | grep -q 'Quit' && e2e_keys q; fi
[ "$(e2e_wait_exit)" = 0 ] || e2e_fail "the console did not exit cleanly"
e2e_output_has 'simulated clock'

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
