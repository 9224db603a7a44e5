#!/usr/bin/env bash
# Regenerates the key reference of docs/configuration.md from `bellows config --markdown`
# (everything from the first "## [" heading on). Usage: scripts/gen-config-docs.sh [path/to/bellows]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
binary="${1:-$root/build/app/bellows}"
doc="$root/docs/configuration.md"
head="$(sed '/^## \[/,$d' "$doc")"
{ printf '%s\n' "$head"; "$binary" config --markdown | sed '1{/^$/d}'; } > "$doc.tmp"
mv "$doc.tmp" "$doc"
