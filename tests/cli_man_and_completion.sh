#!/usr/bin/env bash
# The man page and the bash completion the build generates (app/CMakeLists.txt):
#   tests/cli_man_and_completion.sh path/to/bellows BUILD_DIR
# exist, are current (regenerated, they are the same), hold every subcommand and option of every
# `bellows ... --help`, complete as bash would call them (COMP_WORDS), and `cmake --install` puts
# them and the binary where man and bash-completion look.
set -euo pipefail
bellows="$(realpath "${1:?usage: $0 path/to/bellows BUILD_DIR}")"
build="$(realpath "${2:?usage: $0 path/to/bellows BUILD_DIR}")"
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
man_page="$build/share/man/man1/bellows.1"
completion="$build/share/bash-completion/completions/bellows"
work="$(mktemp -d "${TMPDIR:-/tmp}/cli_man_and_completion-XXXXXX")"
trap 'rm -rf "$work"' EXIT
cd "$work"  # file-name completion sees an empty directory
fail() { echo "FAIL: $*" >&2; exit 1; }

[ -s "$man_page" ] || fail "no man page at $man_page"
[ -s "$completion" ] || fail "no bash completion at $completion"

# Current: generated again from today's binary, the same (the man page's date line aside).
"$bellows" completion bash | diff -u "$completion" - || fail "the completion is stale"
bash "$source_dir/scripts/gen-man-page.sh" "$bellows" "$work/bellows.1"
diff -u <(grep -v '^\.TH' "$man_page") <(grep -v '^\.TH' "$work/bellows.1") || fail "the man page is stale"

# complete_words WORD...: what the completion offers for the last word, one a line.
complete_words() {
  bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _bellows; printf "%s\n" "${COMPREPLY[@]}"' \
    _ "$completion" "$@"
}
expect_offered() {  # expect_offered WANTED WORD...
  local wanted="$1"
  shift
  local offered
  offered="$(complete_words "$@")"  # whole before grep -q: its early exit would fail a pipe under pipefail
  grep -qxF -- "$wanted" <<<"$offered" || fail "'$*' does not offer '$wanted' (offers: $(tr '\n' ' ' <<<"$offered"))"
}
expect_offered run bellows ru
expect_offered --iterations bellows run --ite
expect_offered export bellows sessions ex
expect_offered wall bellows run --clock w
expect_offered try bellows run --rt t
expect_offered csv bellows sessions export --format c
expect_offered --format bellows sessions export --data-dir /tmp --fo  # an option's value is skipped
# Options without a command are the console's: offered first, their values after them.
expect_offered --speed bellows --sp
expect_offered --version bellows --ver
expect_offered max bellows --speed m
expect_offered --trajectory bellows --seed 3 --tra
[ "$(complete_words bellows run --ite)" = "--iterations" ] || fail "run --ite: $(complete_words bellows run --ite)"
[ -z "$(complete_words bellows com)" ] || fail "the hidden completion subcommand is offered"

# Every subcommand and option that some --help lists: offered by the completion, in the man page.
man_text="$(sed 's/\\-/-/g' "$man_page")"
subcommands_of() { "$bellows" "$@" --help | awk '/^Subcommands:/ { on = 1; next } on && /^  [a-z]/ { print $1 } on && /^$/ { on = 0 }'; }
options_of() { "$bellows" "$@" --help | awk '/^Options:/ { on = 1; next } on && /^  -/ { print $1 } on && /^$/ { on = 0 }' | tr ',' '\n'; }
checked=0
check_command() {
  local sub option
  for option in $(options_of "$@"); do
    expect_offered "$option" bellows "$@" "$option"
    grep -qF -- "$option" <<<"$man_text" || fail "bellows $* $option is not in the man page"
    checked=$((checked + 1))
  done
  for sub in $(subcommands_of "$@"); do
    expect_offered "$sub" bellows "$@" "$sub"
    local name="bellows${*:+ $*} $sub"
    grep -qxF ".SS \"$name\"" <<<"$man_text" || fail "$name has no section in the man page"
    check_command "$@" "$sub"
  done
}
check_command
[ "$checked" -gt 50 ] || fail "only $checked options found in the help: is its format still understood?"

# Installed into a fresh prefix: the binary, the page, the completion, and bash picks it up.
cmake --install "$build" --prefix "$work/prefix" > /dev/null
[ -x "$work/prefix/bin/bellows" ] || fail "no bin/bellows installed"
[ -s "$work/prefix/share/man/man1/bellows.1" ] || fail "no share/man/man1/bellows.1 installed"
installed="$work/prefix/share/bash-completion/completions/bellows"
[ -s "$installed" ] || fail "no share/bash-completion/completions/bellows installed"
registered="$(bash -c "source '$installed'; complete -p bellows")"
grep -q -- '-F _bellows bellows' <<<"$registered" || fail "the installed completion is not registered: $registered"
version="$("$work/prefix/bin/bellows" --version)"
grep -q '^bellows ' <<<"$version" || fail "the installed bellows does not run: $version"
echo "ok: $checked options and every subcommand in the man page and the completion; installed"
