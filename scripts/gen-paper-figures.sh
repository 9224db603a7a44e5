#!/usr/bin/env bash
# The figures in docs/figures/: a 10-iteration session of the paper trajectory on the simulated
# arm (seed 1), drawn with `bellows sessions plot --style paper-column` as PNG and PDF, the paper's
# RMS curve overlaid when ../shared/data/paper_rms.csv is beside the checkout.
#   scripts/gen-paper-figures.sh build-test/app/bellows
set -euo pipefail
bellows=$(realpath "${1:?usage: $0 path/to/bellows}")
out=$(realpath "$(dirname "$0")/../docs/figures")
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
XDG_DATA_HOME="$scratch" "$bellows" run --trajectory paper --iterations 10 --seed 1 >/dev/null
session=$(ls "$scratch/bellows/sessions")
mkdir -p "$out"
XDG_DATA_HOME="$scratch" "$bellows" sessions plot "$session" --style paper-column --formats png,pdf \
  --output "$scratch/figures"
for f in "$scratch"/figures/*.png "$scratch"/figures/*.pdf; do cp "$f" "$out/paper-column_$(basename "$f")"; done
echo "figures in $out"
