#!/usr/bin/env bash
# Rig links under load (issues 22 and 25): `bellows run --device lcm|t7 --clock wall --iterations N
# --json` against its simulator (io-sim over LCM, or t7-sim over Modbus TCP on 127.0.0.1), RUNS times
# on an otherwise idle machine and RUNS times with two CPU-bound processes (`yes >/dev/null`) beside
# it. Everything runs in a private network namespace (`unshare -n`: loopback up, multicast on lo),
# so no traffic leaves it. Per run it prints the exit status and fault, the RMS of each iteration
# against the in-process simulated arm's (same seed), and the link's figures: missed deadlines,
# held ticks and samples (ride-through), stale readings, link errors, (LCM) where the engine's reads
# sit after the rig's states and how far its ticks were moved to get there, round trip p50/p99/max, and a
# verdict (PASS: every iteration's RMS within 15 % of the in-process arm's); after each load a
# summary "N of M within 15 %", and the machine's load average (uptime) before and after.
# Usage: bench/rig_links.sh [--device lcm|t7|both] [--runs 10] [--iterations 3] [--bellows PATH]
#                           [--loads "0 2"] [--config FILE]
# Exit status 0 when every run passed, 1 otherwise.
set -euo pipefail
device=lcm runs=10 iterations=3 loads="0 2" config=""
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bellows="$root/build/app/bellows"
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --iterations) iterations="$2"; shift 2 ;;
    --bellows) bellows="$2"; shift 2 ;;
    --loads) loads="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    *) echo "rig_links.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
case "$device" in lcm|t7) devices="$device" ;; both) devices="lcm t7" ;; *) echo "rig_links.sh: --device lcm, t7 or both" >&2; exit 2 ;; esac
bellows="$(realpath "$bellows")"

if [ -z "${RIG_LINKS_IN_NAMESPACE:-}" ]; then  # into a private network namespace first
  exec env RIG_LINKS_IN_NAMESPACE=1 unshare -n -- "$0" --device "$device" --runs "$runs" --iterations "$iterations" \
    --bellows "$bellows" --loads "$loads" ${config:+--config "$config"}
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo

work="$(mktemp -d)"
sim_pid="" load_pids=""
cleanup() {
  [ -n "$sim_pid" ] && kill -INT "$sim_pid" 2>/dev/null || true
  for p in $load_pids; do kill "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
config_args=()
[ -n "$config" ] && config_args=(--config "$(realpath "$config")")

"$bellows" run --iterations "$iterations" --json --no-save "${config_args[@]}" 2>/dev/null > "$work/reference.json"
port=5020
echo "device $devices, $runs runs per load, --iterations $iterations, $(nproc) cores, $(uname -r)"
echo "reference (in-process arm): $(python3 -c 'import json,sys; print(" / ".join("%.3f" % i["rms_deg"] for i in json.load(open(sys.argv[1]))["iterations"]))' "$work/reference.json")"
echo "uptime at start: $(uptime)"
all_passed=0 all_runs=0
for device in $devices; do
for load in $loads; do
  load_pids=""
  for _ in $(seq 1 "$load"); do yes > /dev/null & load_pids="$load_pids $!"; done
  passed=0
  for run in $(seq 1 "$runs"); do
    if [ "$device" = lcm ]; then
      "$bellows" io-sim "${config_args[@]}" > /dev/null 2> "$work/sim.err" & sim_pid=$!
      args=(--device lcm)
    else
      port=$((port + 1))
      "$bellows" t7-sim --listen "127.0.0.1:$port" "${config_args[@]}" > "$work/sim.out" 2> "$work/sim.err" & sim_pid=$!
      args=(--device t7 --t7 "127.0.0.1:$port")
    fi
    sleep 0.5
    status=0
    "$bellows" run "${args[@]}" --clock wall --rt try --iterations "$iterations" --json --no-save "${config_args[@]}" \
      > "$work/run.json" 2> "$work/run.err" || status=$?
    kill -INT "$sim_pid" 2>/dev/null || true
    wait "$sim_pid" 2>/dev/null || true
    sim_pid=""
    verdict=0
    python3 - "$work/reference.json" "$work/run.json" "$status" "$load" "$run" "$(cut -d' ' -f1 /proc/loadavg)" "$device" <<'PY' || verdict=$?
import json, sys
ref = [i["rms_deg"] for i in json.load(open(sys.argv[1]))["iterations"]]
status, load, run, loadavg, device = sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6], sys.argv[7]
try:
    r = json.load(open(sys.argv[2]))
except Exception:
    print(f"FAIL {device} load {load} run {run:>2}: exit {status}, no report"); sys.exit(1)
rms = [i["rms_deg"] for i in r.get("iterations", [])]
within = len(rms) == len(ref) and all(abs(a - b) <= 0.15 * b for a, b in zip(rms, ref))
loop = r.get("loop", {}); link = loop.get("link", {}); rt = link.get("round_trip_ms", {})
held = sum(i.get("held_samples", 0) for i in r.get("iterations", []))
def phase(p):  # LCM: where the engine's reads sit after the rig's states (docs/lcm-protocol.md "Timing")
    return "" if not p else f"phase lead {p['lead_ms']:.2f} ms (shifted {p['shifted_ms']:+.1f}) "

fault = r.get("fault", {}).get("name", "-")
print(f"{'PASS' if within else 'FAIL'} {device} load {load} run {run:>2}: exit {status} fault {fault:<14} "
      f"rms {' / '.join('%.3f' % x for x in rms):<30} {'within 15%' if within else 'OUTSIDE 15%'}  "
      f"missed {loop.get('missed', '?')} held ticks {loop.get('held_ticks', '?')} "
      f"samples {held} stale {link.get('stale_readings', '?')} link errors {link.get('errors', '?')} "
      f"{'late readings used %s ' % r['t7'].get('late_readings', '?') if 't7' in r else ''}"
      f"{phase(r.get('lcm', {}).get('rig', {}).get('tick_phase'))}"
      f"rt p50/p99/max {rt.get('p50', 0):.2f}/{rt.get('p99', 0):.2f}/{rt.get('max', 0):.2f} ms  "
      f"loop wake-up max {loop.get('latency_us', {}).get('max', 0) / 1e3:.1f} ms  loadavg {loadavg}")
sys.exit(0 if within else 1)
PY
    if [ "$verdict" = 0 ]; then passed=$((passed + 1)); else { grep -v '^iteration' "$work/run.err" || true; } | tail -n 4 | sed 's/^/     /'; fi
    if [ "$device" = t7 ]; then  # the strict T7 Pro's log of the whole session: no refusal, never two connections
      echo "     t7-sim: $(grep -c '^t7-sim: refused' "$work/sim.out" || true) refusals, $(grep -c '(2 connected)' "$work/sim.out" || true) times two connections; $(tail -n 1 "$work/sim.out")"
    fi
  done
  for p in $load_pids; do kill "$p" 2>/dev/null || true; done
  load_pids=""
  echo "$device with $load CPU-bound processes beside it: $passed of $runs within 15 %  (uptime: $(uptime))"
  all_passed=$((all_passed + passed)) all_runs=$((all_runs + runs))
done
done
echo "summary: $all_passed of $all_runs within 15 %"
[ "$all_passed" = "$all_runs" ]
