#!/usr/bin/env bash
# scripts/console_captures.sh still follows the console (every screen it waits for appears), and
# its captures still fit docs/console.md's markers one to one (scripts/console_captures_into_docs.py
# into a copy of the docs). Keeps the documented screens reproducible.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/e2e_console_captures-XXXXXX")"
trap 'rm -rf "$work"' EXIT
bash "$here/../scripts/console_captures.sh" "$1" "$work/captures"
cp "$here/../docs/console.md" "$work/console.md"
python3 "$here/../scripts/console_captures_into_docs.py" "$work/captures" "$work/console.md"
grep -q 'iterations 0\.\.5, best RMS' "$work/captures/summary.txt" || { echo "FAIL: summary: $(cat "$work/captures/summary.txt")"; exit 1; }
grep -q 'Name this session' "$work/captures/name.txt" || { echo "FAIL: no naming dialog"; exit 1; }
grep -q 'Quit?' "$work/captures/quit.txt" || { echo "FAIL: no quit dialog"; exit 1; }
echo "ok: $(ls "$work/captures" | wc -l) captures, all placed in docs/console.md"
