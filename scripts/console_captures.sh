#!/usr/bin/env bash
# Captures every console screen from the real binary in tmux, for docs/console.md:
#   scripts/console_captures.sh build/app/bellows OUT_DIR [WIDTH HEIGHT]
# One run on the simulated arm (--speed max, --rt off: it never asks for real-time scheduling),
# in a private data directory; each screen goes to OUT_DIR/NAME.txt as `tmux capture-pane -p`
# shows it, and the closing summary to OUT_DIR/summary.txt. The Quit dialog comes from a second,
# short run without a data directory (the console asks only when something is not saved).
# scripts/console_captures_into_docs.py OUT_DIR docs/console.md then puts them into the docs.
set -euo pipefail
out="${2:?usage: $0 path/to/bellows OUT_DIR [WIDTH HEIGHT]}"
width="${3:-100}"
height="${4:-32}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
source "$(dirname "$0")/../tests/e2e_console_lib.sh" "$1"

capture() { sleep 0.5; e2e_screen > "$out/$1.txt"; }

python3 - "$E2E_DIR/wave.csv" <<'EOF'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("time_s,angle_deg\n")
    for i in range(301):
        f.write("%.2f,%.4f\n" % (i * 0.02, 20 * math.sin(2 * math.pi * 0.5 * i * 0.02)))
EOF

e2e_start "$width" "$height" -- console --speed max --rt off
e2e_wait_law_ready
e2e_keys '?'
e2e_wait_for 'Everywhere \(greyed'
capture help-safe
e2e_keys Escape a
e2e_wait_for 'Arm the valves\?'
capture arm
e2e_keys y
e2e_wait_for 'Bellows +ARMED '

e2e_keys N
e2e_wait_for 'Run K iterations'
e2e_keys BSpace BSpace 2 . 5 Enter
e2e_wait_for 'K must be a whole number'
capture ask-k-refused
e2e_keys BSpace BSpace BSpace 5 Enter
e2e_wait_for 'iterations 0\.\.5 done' 300
capture main

e2e_keys c
e2e_wait_for 'At the cursor'
e2e_keys PageDown PageDown PageDown Right Right Right Up Up m Down
e2e_wait_for 'overlay: it 3'
capture inspector
# The study (issue 23): e jumps to the largest |error| of the trial, e again to the next peak; the
# error beside the correction and the comparison with iteration 3, at 80x24 and at 120x40.
e2e_keys e
e2e_wait_for '\|e\| peak +1 of'
e2e_resize 80 24
e2e_wait_for 'Error e'
e2e_wait_for '\|e\| peak +1 of'
capture inspector-worst-80x24
e2e_resize 120 40
e2e_keys e
e2e_wait_for '\|e\| peak +2 of'
e2e_wait_for 'RMS de'
capture inspector-worst-120x40
e2e_resize "$width" "$height"
e2e_wait_for 'At the cursor'
e2e_keys Escape t
e2e_wait_for 'Trajectories'
e2e_keys Down Down Down Down Down Enter  # past paper, steps, sine, paper2, paper3
e2e_wait_for 'Trajectory file'
e2e_keys -l "$E2E_DIR/wave.csv"
e2e_keys Enter
e2e_wait_for 'wave: 6.0 s'
capture trajectory-file
e2e_keys Escape w
e2e_wait_for 'Gains, learning law and weights'
capture tuning
e2e_keys Escape s
e2e_wait_for 'Name this session'
capture name
for _ in $(seq 1 60); do e2e_keys BSpace; done
e2e_keys -l captures
e2e_keys Enter
e2e_wait_for 'named: .*/captures'
e2e_keys l
e2e_wait_for 'Event log'
capture log
e2e_keys Escape d
e2e_wait_for 'Bellows +SAFE '
e2e_keys o
e2e_wait_for 'best RMS'
capture sessions
e2e_keys Escape a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r Space  # a trial starts and is stopped at once (at --speed max it would be over before a look)
e2e_wait_for 'Last ticks before the fault'
capture fault
e2e_resize 70 20
e2e_wait_for 'Terminal too small'
capture too-small
e2e_resize "$width" "$height"
e2e_wait_for 'R Reset'
e2e_keys q
sleep 1
e2e_screen_has 'Quit?' && e2e_keys q
e2e_wait_exit > /dev/null
e2e_history | grep -A3 '^bellows console:' | grep -v '^EXIT STATUS' > "$out/summary.txt"

# Quit asks only when something would be lost: here nothing can be saved (no data directory).
e2e_start "$width" "$height" XDG_DATA_HOME= HOME= -- console --speed max --rt off
e2e_wait_law_ready
e2e_keys a
e2e_wait_for 'Arm the valves\?'
e2e_keys y
e2e_wait_for 'Bellows +ARMED '
e2e_keys r
e2e_wait_for 'iteration 0  RMS' 120
e2e_keys q
e2e_wait_for 'Quit\?'
capture quit
e2e_keys q
e2e_wait_exit > /dev/null
echo "captures in $out: $(ls "$out" | tr '\n' ' ')"
