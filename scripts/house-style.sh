#!/usr/bin/env bash
# The house style (.clang-format at the root) on every C++ file of the repository, tracked or new:
#   scripts/house-style.sh            check: clang-format --dry-run --Werror, names each file out of style
#   scripts/house-style.sh --fix      rewrite them in the style (what `scripts/dev format` runs)
#   scripts/house-style.sh --planted  show that the check refuses a file out of style (a ctest)
# and one rule on every shell script: no pipe into `grep -q`. grep leaves at its first match, the
# writer still writing gets SIGPIPE, and under `set -o pipefail` the match reads as a failure (it
# failed e2e_console_autosave once in CI). Match a captured text instead: grep -q ... <<<"$text".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
format="$(command -v clang-format || command -v clang-format-14 || true)"
[ -n "$format" ] || { echo "house style: clang-format is not installed (scripts/setup.sh installs it)" >&2; exit 2; }
files() { git ls-files --cached --others --exclude-standard -- '*.cpp' '*.hpp' '*.h' '*.cxx'; }
scripts() { git ls-files --cached --others --exclude-standard -- '*.sh'; }
# pipes_into_grep_q FILE...: prints each line (not a comment) with a pipe, not `||`, into grep -q;
# fails if there is one.
pipes_into_grep_q() {
  local hits
  hits="$(grep -nHE '(^|[^|])\|[^|]*\bgrep +(-[a-zA-Z-]+ +)*-[a-zA-Z]*q' "$@" | grep -vE '^[^:]*:[0-9]+:[[:space:]]*#' || true)"
  [ -z "$hits" ] || { echo "$hits"; return 1; }
}
case "${1:-}" in
  "")
    if ! files | xargs -r "$format" --dry-run --Werror; then
      echo "house style: the files above are not in the style of .clang-format: scripts/dev format rewrites them" >&2
      exit 1
    fi
    if ! scripts | xargs -r bash -c "$(declare -f pipes_into_grep_q); pipes_into_grep_q \"\$@\"" _; then
      echo "house style: the lines above pipe into grep -q, which fails under pipefail when grep leaves early: grep -q ... <<<\"\$text\"" >&2
      exit 1
    fi
    ;;
  --fix)
    files | xargs -r "$format" -i
    ;;
  --planted)
    # A file of the tree in the style, then the same with one line indented by a stray space.
    dir="$(mktemp -d)"
    trap 'rm -rf "$dir"' EXIT
    cp .clang-format "$dir/"
    cp engine/base/errors.hpp "$dir/in_style.hpp"
    "$format" --dry-run --Werror "$dir/in_style.hpp" || { echo "house style: engine/base/errors.hpp is not in the style" >&2; exit 1; }
    sed '0,/^namespace/s/^namespace/ namespace/' "$dir/in_style.hpp" > "$dir/planted.hpp"
    if "$format" --dry-run --Werror "$dir/planted.hpp" 2> /dev/null; then
      echo "house style: the check passed a file out of style" >&2
      exit 1
    fi
    echo "house style: the check refuses a file out of style"
    printf '%s\n' 'set -o pipefail' 'x="$(seq 3)"' 'grep -q 2 <<<"$x" || grep -q 3 <<<"$x"' > "$dir/in_style.sh"
    pipes_into_grep_q "$dir/in_style.sh" || { echo "house style: the shell rule refused a script in the style" >&2; exit 1; }
    printf 'set -o pipefail\nseq 100000 %s grep -q 2\n' '|' > "$dir/planted.sh"
    if pipes_into_grep_q "$dir/planted.sh" > /dev/null; then
      echo "house style: the shell rule passed a pipe into grep -q" >&2
      exit 1
    fi
    echo "house style: the shell rule refuses a pipe into grep -q"
    ;;
  *)
    echo "usage: scripts/house-style.sh [--fix|--planted]" >&2
    exit 2
    ;;
esac
