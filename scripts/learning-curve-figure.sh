#!/usr/bin/env bash
# The learning-curve figure of docs/learning-laws.md: RMS error per iteration on the paper trajectory
# (simulated arm, seed 1, default configuration) for the paper's law (noilc) and noilc-learned, with the
# paper's measured curve (/work/shared/data/paper_rms.csv or $PAPER_RMS). gnuplot, pngcairo, as
# `bellows plot` draws (app/plot_figures.cpp). Usage: scripts/learning-curve-figure.sh [bellows] [iterations]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
binary="${1:-$root/build/app/bellows}"
iterations="${2:-100}"
paper="${PAPER_RMS:-/work/shared/data/paper_rms.csv}"
out="$root/docs/figures"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for law in noilc noilc-learned; do
  printf '[ilc]\nlaw = "%s"\n' "$law" > "$work/$law.toml"
  nice -n 10 "$binary" run --trajectory paper --seed 1 --iterations "$iterations" --json --no-save -q --config "$work/$law.toml" |
    python3 -c 'import json, sys
for it in json.load(sys.stdin)["iterations"]: print(it["iteration"], it["rms_deg"])' > "$work/$law.dat"
done
tail -n +2 "$paper" | tr ',' ' ' > "$work/paper.dat"
mkdir -p "$out"
gnuplot <<GNUPLOT
set terminal pngcairo size 1200,800 noenhanced font ',12'
set output '$out/learning-curve-paper.png'
set title 'paper trajectory, simulated arm, seed 1: RMS error per iteration'
set xlabel 'iteration'
set ylabel 'RMS error (deg)'
set logscale y
set grid
set key top right
plot '$work/noilc.dat' using 1:2 with linespoints pt 7 ps 0.6 title 'noilc (paper law, default)', \
     '$work/noilc-learned.dat' using 1:2 with linespoints pt 5 ps 0.6 title 'noilc-learned', \
     '$work/paper.dat' using 1:2 with linespoints pt 9 ps 0.8 title 'the paper (its arm)'
GNUPLOT
echo "wrote $out/learning-curve-paper.png"
