#!/usr/bin/env bash
# Wake-up latency of the engine thread against cyclictest (Debian's rt-tests), side by side on the
# same machine for the same time, both at 200 Hz, SCHED_FIFO priority 80, memory locked.
# Usage: bench/rt_latency.sh [seconds] [path/to/bellows]. Prints one JSON object.
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bellows="${2:-$root/build/app/bellows}"
command -v cyclictest >/dev/null || { echo "cyclictest missing: run scripts/setup.sh" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Iterations of the paper trajectory (9 s each with the settle) that fill the time.
iterations=$(( seconds / 9 ))
[ "$iterations" -ge 1 ] || iterations=1
# cyclictest runs from before the engine's first tick until after its last one, so that both
# distributions cover the same stretch of time (the engine also spends a few seconds arming and
# settling beyond the trials' own time). SIGINT makes cyclictest write its histogram and exit.
cyclictest --priority=80 --interval=5000 --threads=1 --mlockall --quiet \
  --histogram=20000 --histfile="$work/cyclic.hist" > /dev/null 2>&1 &
cyclic_pid=$!
sleep 1
"$bellows" run --clock wall --speed 1 --rt try --iterations "$iterations" --json 2>/dev/null > "$work/engine.json"
kill -INT "$cyclic_pid"
wait "$cyclic_pid" || true

python3 - "$work/cyclic.hist" "$work/engine.json" <<'PY'
import json, sys
hist, engine = sys.argv[1], json.load(open(sys.argv[2]))
counts, maximum = [], 0
for line in open(hist):
    if line.startswith('#'):
        if 'Max Latencies' in line: maximum = int(line.split(':')[1].split()[0])
        continue
    parts = line.split()
    if len(parts) >= 2: counts.append((int(parts[0]), int(parts[1])))
total = sum(c for _, c in counts)
def quantile(q):
    seen = 0
    for us, c in counts:
        seen += c
        if seen > q * total: return us
    return counts[-1][0] if counts else 0
loop = engine.get('loop', {})
print(json.dumps({'cyclictest': {'samples': total, 'p50_us': quantile(0.5), 'p99_us': quantile(0.99), 'max_us': maximum},
                  'engine': {'ticks': loop.get('ticks'), 'missed': loop.get('missed'), 'rt': loop.get('rt'),
                             'cpu_wakeup_limit_us': loop.get('cpu_wakeup_limit_us'),
                             'p50_us': loop.get('latency_us', {}).get('p50'), 'p99_us': loop.get('latency_us', {}).get('p99'),
                             'max_us': loop.get('latency_us', {}).get('max')},
                  'final_rms_deg': engine['iterations'][-1]['rms_deg'] if engine.get('iterations') else None}))
PY
