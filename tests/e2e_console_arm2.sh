#!/usr/bin/env bash
# The console drives arm2 end to end (issue 14): `[arm] preset = "arm2"` on the simulated chain with
# `paper2`; arm, run iterations 0..3 and read each joint's RMS and the overall one off the screen,
# inspect the correction of joint 2 (the elbow), emergency stop with the elbow's black box, quit
# (saved as it went), reopen the session: the same per-joint history, joint 2 inspected again.
source "$(dirname "$0")/e2e_console_lib.sh"

# The dashboard's RMS list on an arm with two joints, as "iteration all j1 j2" lines.
arm2_rms_list() {
  e2e_screen | grep -oE ' +[0-9]+ +[0-9]+\.[0-9]{3}\*? +[0-9]+\.[0-9]{3} +[0-9]+\.[0-9]{3}[│|]' |
    sed -E 's/[*│|]//g; s/^ +//; s/ +/ /g'
}

# The prediction on the nominal model alone (one grid point): its 5 x 5 grid is tested where it is
# computed and reported (test_joint_convergence, CliJoints.Arm2Reports...), not on the screen here.
printf '[arm]\npreset = "arm2"\n[ilc]\nprediction_grid_points = 1\n' >"$E2E_DIR/arm2.toml"
e2e_start 120 40 -- console --speed max --config "$E2E_DIR/arm2.toml" --trajectory paper2
e2e_wait_for 'Bellows +SAFE '
e2e_wait_for 'trajectory paper2 \(8\.0 s\)  joint 1/2 shoulder'
e2e_wait_law_ready

e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '

# Iterations 0..3: feedback only, then three learned corrections on both joints.
e2e_keys N
e2e_wait_for 'Run K iterations'
e2e_keys BSpace BSpace 3 Enter
e2e_wait_for 'iterations 0\.\.3 done' 300
e2e_wait_for 'it +all +j1 +j2'
rms="$(arm2_rms_list)"
[ "$(echo "$rms" | awk '{print $1}' | tr '\n' ' ')" = "0 1 2 3 " ] || e2e_fail "RMS list: $rms"
# Each joint's RMS falls from iteration 0 to 3, and the overall one is the RMS over both joints.
first="$(echo "$rms" | head -1)"
last="$(echo "$rms" | tail -1)"
for column in 2 3 4; do
  awk -v a="$(echo "$first" | cut -d' ' -f$column)" -v b="$(echo "$last" | cut -d' ' -f$column)" 'BEGIN { exit !(b < a) }' ||
    e2e_fail "column $column of the RMS list did not fall: $first -> $last"
done
echo "$rms" | awk '{ o = sqrt(($3 * $3 + $4 * $4) / 2); if (o - $2 > 0.002 || $2 - o > 0.002) bad = 1 } END { exit bad }' ||
  e2e_fail "the overall RMS is not the RMS over both joints: $(echo "$rms" | tr '\n' ';')"
overall="$(echo "$last" | cut -d' ' -f2)"
elbow="$(echo "$last" | cut -d' ' -f4)"
e2e_wait_for "iteration 3  RMS $overall deg"

# The correction inspector on joint 2: j selects the elbow, its RMS and its signals.
e2e_keys c
e2e_wait_for 'At the cursor'
e2e_wait_for 'Iteration 3 of 0\.\.3  joint 1/2 shoulder'
e2e_keys j
e2e_wait_for "Iteration 3 of 0\.\.3  joint 2/2 elbow .*\(joint 2 $elbow\)"
e2e_keys PageDown PageDown
e2e_wait_for 'time +1\.60 s'

# Emergency stop: FAULT, and the black box of the selected joint.
e2e_keys Space
e2e_wait_for 'FAULT: emergency-stop'
e2e_wait_for 'Last ticks before the fault, joint 2/2 elbow'
e2e_keys R
e2e_wait_for 'Bellows +SAFE '

# Saved as it went: quit does not ask; the closing report names the session.
e2e_keys Escape
e2e_wait_for 'it +all +j1 +j2'
for _ in $(seq 1 100); do e2e_screen_has 'unsaved' || break; sleep 0.1; done
e2e_quit
status="$(e2e_wait_exit)"
[ "$status" = "0" ] || e2e_fail "exit status $status"
e2e_output_has 'bellows console: .* iterations 0\.\.3, best RMS .*valves vented'
e2e_output_has 'session: /.* \(saved as it went\)'
session="$(e2e_history | grep -oE '^session: /[^ ]+' | head -1 | cut -c10-)"
[ -f "$session/manifest.json" ] || e2e_fail "no session at '$session'"
shown="$("$BELLOWS" sessions show "$session")"
grep -q '2 joints' <<<"$shown" || e2e_fail "sessions show does not say 2 joints: $shown"

# Reopened: the arm of the session (arm2), the same per-joint RMS history, joint 2 inspected again.
e2e_start 120 40 -- console --speed max --session "$session"
e2e_wait_for 'trajectory paper2 \(8\.0 s\)  joint 1/2 shoulder'
e2e_wait_for 'it +all +j1 +j2'
[ "$(arm2_rms_list)" = "$rms" ] || e2e_fail "RMS history after reopening: $(arm2_rms_list | tr '\n' ';') vs $(echo "$rms" | tr '\n' ';')"
e2e_keys c
e2e_wait_for 'At the cursor'
e2e_keys j
e2e_wait_for "Iteration 3 of 0\.\.3  joint 2/2 elbow .*\(joint 2 $elbow\)"
e2e_keys Escape
e2e_quit
[ "$(e2e_wait_exit)" = "0" ] || e2e_fail "exit status after reopening"
echo "ok: $(echo "$rms" | tr '\n' ';')"
