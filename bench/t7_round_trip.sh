#!/usr/bin/env bash
# The Modbus round trip of `--device t7` on loopback: bellows t7-sim and bellows run --device t7 as
# two processes on 127.0.0.1 for about [seconds] of trials. Prints run's "loop" object (its "link"
# holds the round trip p50/p99/max in ms over the last 4096 exchanges, and the max since connect).
# Usage: bench/t7_round_trip.sh [seconds] [path/to/bellows] [port]
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bellows="${2:-$root/build/app/bellows}"
port="${3:-5020}"
work="$(mktemp -d)"
"$bellows" t7-sim --listen "127.0.0.1:$port" > "$work/sim.out" &
sim_pid=$!
trap 'kill "$sim_pid" 2>/dev/null || true; rm -rf "$work"' EXIT
sleep 1
# Iterations of the paper trajectory (9 s each with the settle) that fill the time.
iterations=$(( seconds / 9 - 1 ))
[ "$iterations" -ge 0 ] || iterations=0
"$bellows" run --device t7 --t7 "127.0.0.1:$port" --clock wall --rt try --iterations "$iterations" --json --no-save \
  2>/dev/null > "$work/run.json"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(json.dumps({"iterations": len(r["iterations"]), "loop": r["loop"]}))' "$work/run.json"
