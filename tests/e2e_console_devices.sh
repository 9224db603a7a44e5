#!/usr/bin/env bash
# The console drives every device: for each one (default: sim lcm t7) arm, one iteration, emergency
# stop, save, quit; then the saved session reopens in the console on the device it was made on,
# and the Rig screen's valve test passes every valve. The LCM rig is `bellows io-sim` over UDP
# multicast inside a private network namespace this script makes for itself (`unshare -n`, loopback
# multicast set up inside it only): nothing leaves the namespace. The T7 is `bellows t7-sim` on
# 127.0.0.1 at a port the kernel picks (the console gets it from t7-sim's first line).
#
# usage: e2e_console_devices.sh path/to/bellows [DEVICE...]
# A device is one line in device_setup below: what to start beside the console, and its options.
BELLOWS_ARG="${1:?usage: $0 path/to/bellows [DEVICE...]}"
if [ -z "${BELLOWS_E2E_NETNS:-}" ]; then
  if ! command -v unshare >/dev/null || ! unshare -n true 2>/dev/null; then
    echo "SKIP: cannot make a private network namespace (unshare -n); the LCM rig needs one"
    exit 0
  fi
  exec env BELLOWS_E2E_NETNS=1 unshare -n bash "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo

source "$(dirname "$0")/e2e_console_lib.sh"
shift
DEVICES=("$@")
[ ${#DEVICES[@]} -gt 0 ] || DEVICES=(sim lcm t7)

RIG_PID=""
stop_rig() {
  if [ -n "$RIG_PID" ]; then
    kill -TERM "$RIG_PID" 2>/dev/null || true
    wait "$RIG_PID" 2>/dev/null || true
    RIG_PID=""
  fi
}
trap 'stop_rig; e2e_cleanup' EXIT

# device_setup DEVICE: starts what the device needs beside the console and sets DEVICE_ARGS.
device_setup() {
  case "$1" in
    sim) DEVICE_ARGS=(--device sim --speed 2) ;;
    # Over LCM a reading lags its command by a state period or two: the valve test's pulses must
    # be long against that lag (docs/rig-bring-up.md), so this rig gets longer ones. And the
    # loaded-machine guards of the t7 rig below: io-sim without real-time priority beside other
    # tests and builds can fall silent for longer than a rig may (its guards have tests of their own).
    # The rig's own command timeout is loaded-machine too: a console engine stalled by a build
    # beside it (118 ms seen) would otherwise trip the rig (rig-timeout, which has tests of its own).
    lcm) printf '[rig_check]\nfill_s = 0.1\nvalve_pulse_s = 0.1\n[safety]\nstale_ticks = 400\nmissed_deadline_streak = 100000\n[lcm]\nrig_timeout_s = 2.0\n' \
           >"$E2E_DIR/lcm-rig.toml"
         "$BELLOWS" io-sim --rt off --config "$E2E_DIR/lcm-rig.toml" >"$E2E_DIR/io-sim.out" 2>&1 & RIG_PID=$!
         DEVICE_ARGS=(--device lcm --config "$E2E_DIR/lcm-rig.toml") ;;
    # Loopback only, on a free port: t7-sim says which one it got on its first line.
    # One answer 0.6 s late, 1 s after connecting: the link's lines (it stopped answering, it answers
    # again) go to the console's log, not across the screen.
    t7)  "$BELLOWS" t7-sim --listen 127.0.0.1:0 --stall-after 1 --stall-s 0.6 >"$E2E_DIR/t7-sim.out" 2>&1 & RIG_PID=$!
         local port="" tries=0
         while [ -z "$port" ]; do
           port="$(grep -oE 'on 127\.0\.0\.1:[0-9]+' "$E2E_DIR/t7-sim.out" | head -1 | cut -d: -f2 || true)"
           kill -0 "$RIG_PID" 2>/dev/null || e2e_fail "t7-sim did not start: $(cat "$E2E_DIR/t7-sim.out")"
           tries=$((tries + 1)); [ "$tries" -lt 200 ] || e2e_fail "t7-sim never said its port"
           [ -n "$port" ] || sleep 0.05
         done
         [ "$port" != 0 ] || e2e_fail "t7-sim reports port 0"
         # The loaded-machine settings of the T7 process tests: a sanitizer build beside other
         # tests answers Modbus slower than a rig's 20 ms timeout allows (what the guards do on a
         # real link has tests of its own).
         printf '[t7]\nresponse_timeout_s = 0.5\n[safety]\nstale_ticks = 400\nmissed_deadline_streak = 100000\n' >"$E2E_DIR/t7-loaded.toml"
         # A rig profile with an identified [model] (the paper rig's wiring): the console learns
         # with it, says so in its log, and the session records where its model came from.
         { cat "$(dirname "$0")/../profiles/paper-rig.toml"
           printf '\n[model]\nkappa_rad_per_bar = 7.5\nomega0_rad_per_s = 14.0\ndamping = 0.3\n'; } >"$E2E_DIR/t7-rig.toml"
         DEVICE_ARGS=(--device t7 --t7 "127.0.0.1:$port" --rig-profile "$E2E_DIR/t7-rig.toml" --config "$E2E_DIR/t7-loaded.toml") ;;
    *) e2e_fail "unknown device '$1'" ;;
  esac
}

for device in "${DEVICES[@]}"; do
  device_setup "$device"
  e2e_start 120 40 -- console "${DEVICE_ARGS[@]}" --trajectory steps
  e2e_wait_for 'Bellows +SAFE '
  e2e_wait_for "(device )?$device: ok"
  e2e_wait_law_ready
  if [ "$device" = t7 ]; then
    e2e_keys l
    e2e_wait_for 'device +t7 link 127\.0\.0\.1:[0-9]+ answers again'
    ! e2e_screen_has -F 'bellows: t7 link' || e2e_fail "t7: the link's stderr lines were painted over the screen"
    e2e_keys Escape
    e2e_wait_for '─ Live ─'
  fi

  # Arm, one iteration.
  e2e_keys a
  e2e_wait_for 'Arm the valves\?'
  e2e_keys y
  e2e_wait_for 'Bellows +ARMED '
  e2e_keys r
  e2e_wait_for 'it(eration)? 0  RMS' 120  # iteration 0 ran

  # Emergency stop: FAULT, vented.
  e2e_keys Space
  e2e_wait_for 'FAULT: emergency-stop'
  e2e_keys R
  e2e_wait_for 'Bellows +SAFE '

  # The Rig screen: the inputs, then the valve test (asks first), every valve passes.
  e2e_keys b
  e2e_wait_for "Inputs: $device"
  # The chamber pressure row: "chamber A" as the engine reads it, or the rig's raw input "chamber_a"
  # once its volts arrive (which one the first frame shows is a race).
  e2e_wait_for 'chamber( A|_a) '
  if [ "$device" = t7 ]; then
    # The zero-angle question (a T7 with a rig profile only; issue 23: a test per prompt): command
    # letters are named as no answer and leave it open, Esc closes it, the profile is unchanged.
    profile_before="$(sha256sum < "$E2E_DIR/t7-rig.toml")"
    zero_letters='brdaxtcwlsofgHjTRv?zmue'  # every command key but the answers y, n (and q)
    e2e_keys z
    e2e_wait_for 'Zero the angle here\?'
    e2e_keys -l -- "$zero_letters"
    e2e_wait_for 'e is not an answer here'
    e2e_screen_has -F 'Zero the angle here?' || e2e_fail "t7: a letter closed the zero-angle question"
    e2e_keys Escape
    e2e_wait_gone 'Zero the angle here\?' 10  # "still ... on the screen": Esc left the question open
    e2e_screen_has -E 'Bellows +SAFE ' || e2e_fail "t7: not SAFE after the zero-angle question"
    [ "$(sha256sum < "$E2E_DIR/t7-rig.toml")" = "$profile_before" ] || e2e_fail "t7: the rig profile changed"
  fi
  e2e_keys v
  e2e_wait_for 'Valve test: open each valve alone\?'
  e2e_keys y
  e2e_wait_for 'outlet B +(pass|FAIL)' 120  # the table stays; the status line moves on
  for valve in 'inlet A' 'inlet B' 'outlet A' 'outlet B'; do
    e2e_screen_has -E "$valve +pass" || e2e_fail "$device: $valve did not pass"
  done
  e2e_keys Escape

  # Quit: the session was saved as it went; the valves are vented before the exit.
  e2e_quit
  [ "$(e2e_wait_exit)" = "0" ] || e2e_fail "$device: exit status after quit"
  e2e_output_has 'valves vented'
  session="$(e2e_history | grep -oE 'session: /[^ ]+ \(saved as it went\)' | head -1 | cut -d' ' -f2)"
  [ -f "$session/manifest.json" ] || e2e_fail "$device: no session at '$session'"
  grep -q "\"device\": *\"$device\"" "$session/manifest.json" || e2e_fail "$device: the session does not record its device"
  if [ "$device" = t7 ]; then
    grep -q '"source": *"rig_profile"' "$session/manifest.json" || e2e_fail "t7: the session does not say its model is the rig profile's"
    grep -q '"kappa_rad_per_bar": *7.5' "$session/manifest.json" || e2e_fail "t7: the session's model is not the rig profile's"
    grep -q "learning with the rig profile paper-rig's \[model\] (kappa 7.5" "$session/manifest.json" ||
      e2e_fail "t7: the console's log does not say which model it learns with"
  else
    grep -q '"source": *"configuration"' "$session/manifest.json" || e2e_fail "$device: the session does not say its model is the configuration's"
  fi

  # The session reopens in the console, on the device it was made on.
  # With the device's loaded-machine settings again: a session brings back its device and its arm,
  # not the link's timeouts nor the guards (the console's --config gives them).
  reopen_args=()
  case "$device" in
    sim) reopen_args=(--speed 2) ;;
    *) for ((i = 0; i < ${#DEVICE_ARGS[@]}; ++i)); do
         [ "${DEVICE_ARGS[$i]}" = --config ] && reopen_args=(--config "${DEVICE_ARGS[$((i + 1))]}")
       done ;;
  esac
  e2e_start 120 40 -- console --session "$session" "${reopen_args[@]}"
  e2e_wait_for 'it(eration)? 0  RMS'  # its one iteration, 0
  e2e_wait_for "(device )?$device: ok"
  e2e_quit
  [ "$(e2e_wait_exit)" = "0" ] || e2e_fail "$device: exit status after the reopened session"
  stop_rig
  echo "ok: $device"
done
