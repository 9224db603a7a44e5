#!/usr/bin/env bash
# Writes bellows(1) from the program's own help with help2man (Debian's help2man):
#   scripts/gen-man-page.sh path/to/bellows OUT.1
# `bellows --help` and `--version` give the synopsis, options and version; every subcommand's
# `--help` (found by walking the "Subcommands:" lists, so a new one is never forgotten) goes into a
# SUBCOMMANDS section. The build runs this after linking bellows (CMakeLists.txt) and installs the
# page as share/man/man1/bellows.1.
set -euo pipefail
bellows="${1:?usage: $0 path/to/bellows OUT.1}"
out="${2:?usage: $0 path/to/bellows OUT.1}"
include="$(mktemp)"
trap 'rm -f "$include"' EXIT

# The subcommands listed in the help of `bellows $*`, one a line.
subcommands_of() {
  "$bellows" "$@" --help | awk '/^Subcommands:/ { on = 1; next } on && /^  [a-z]/ { print $1 } on && /^$/ { on = 0 }'
}

# Each subcommand's help as a subsection, its nested subcommands after it.
describe() {
  local sub
  for sub in $(subcommands_of "$@"); do
    printf '.SS "bellows %s"\n.nf\n' "$* $sub" | sed 's/bellows  /bellows /'
    "$bellows" "$@" "$sub" --help | sed -e 's/\\/\\e/g' -e 's/^\./\\\&./' -e "s/^'/\\\\\\&'/"
    printf '.fi\n'
    describe "$@" "$sub"
  done
}

{
  printf '[SUBCOMMANDS]\n'
  describe
  printf '[SEE ALSO]\nThe README and docs/*.md of the source tree: docs/iterations.md (what an iteration is),\n'
  printf 'docs/console.md, docs/configuration.md, docs/session-format.md, docs/rig-bring-up.md.\n'
} > "$include"
mkdir -p "$(dirname "$out")"
help2man --no-info --section 1 --name "iterative learning control for a pneumatic soft robotic arm" \
  --include "$include" --output "$out" "$bellows"
