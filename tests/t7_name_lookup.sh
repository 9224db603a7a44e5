#!/usr/bin/env bash
# A T7 given by a host name whose name server never answers: the connect gives up at [t7]
# connect_timeout_s and says the name service did not answer, instead of waiting out the resolver's
# own timeout (30 s here), and Ctrl-C ends the wait at once (devices/name_lookup.hpp). The script
# runs in private mount and network namespaces it makes for itself: there /etc/resolv.conf names
# 127.0.0.1, where a UDP socket takes the queries and never answers. Nothing leaves the namespace.
#
# usage: t7_name_lookup.sh path/to/bellows path/to/python3
set -euo pipefail
BELLOWS="${1:?usage: $0 path/to/bellows path/to/python3}"
PYTHON="${2:?usage: $0 path/to/bellows path/to/python3}"
if [ -z "${BELLOWS_LOOKUP_NETNS:-}" ]; then
  if ! command -v unshare > /dev/null || ! unshare -m -n true 2> /dev/null; then
    echo "SKIP: cannot make private mount and network namespaces (unshare -m -n)"
    exit 0
  fi
  exec env BELLOWS_LOOKUP_NETNS=1 unshare -m -n bash "$0" "$@"
fi
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
ip link set lo up
dir="$(mktemp -d)"
server=""
trap '[ -n "$server" ] && kill "$server" 2> /dev/null; rm -rf "$dir"' EXIT

# The name server: bound before anything asks it; it answers nothing, and marks each query it takes
# (the file "asked"), so that the script knows when a lookup is waiting on it.
"$PYTHON" -c '
import os, socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", 53))
open(os.path.join(sys.argv[1], "bound"), "w").close()
while True:
    s.recv(4096)
    open(os.path.join(sys.argv[1], "asked"), "w").close()' "$dir" &
server=$!
for _ in $(seq 400); do [ -e "$dir/bound" ] && break; sleep 0.05; done
[ -e "$dir/bound" ] || fail "the silent name server did not start"
printf 'nameserver 127.0.0.1\noptions timeout:30 attempts:1\n' > "$dir/resolv.conf"
mount --bind "$dir/resolv.conf" /etc/resolv.conf  # this mount namespace only
name=t7.bellows-test.invalid                      # in no hosts file: asked of the name server

printf '[t7]\nconnect_timeout_s = 0.5\n' > "$dir/short.toml"
set +e
out="$("$BELLOWS" run --device t7 --t7 "$name:5020" --config "$dir/short.toml" --iterations 0 --no-save 2>&1)"
status=$?
set -e
[ "$status" -eq 4 ] || fail "exit $status, not 4 (the environment refused): $out"
grep -qF "cannot connect within [t7] connect_timeout_s = 0.5 s (cannot resolve $name: the name service did not answer in time)" \
  <<< "$out" || fail "not the lookup's deadline: $out"
[ "$(wc -l <<< "$out")" -eq 1 ] || fail "more than one line: $out"

# Ctrl-C while the lookup waits on the name server (its deadline 20 s away): interrupted at once.
printf '[t7]\nconnect_timeout_s = 20\n' > "$dir/long.toml"
rm -f "$dir/asked"
"$BELLOWS" run --device t7 --t7 "$name:5020" --config "$dir/long.toml" --iterations 0 --no-save \
  > "$dir/interrupted.out" 2>&1 &
run=$!
for _ in $(seq 400); do [ -e "$dir/asked" ] && break; sleep 0.05; done  # the lookup waits: now Ctrl-C
[ -e "$dir/asked" ] || fail "no lookup reached the name server: $(cat "$dir/interrupted.out")"
kill -INT "$run"
set +e
wait "$run"
status=$?
set -e
out="$(cat "$dir/interrupted.out")"
[ "$status" -eq 130 ] || fail "exit $status after SIGINT, not 130: $out"
grep -qF "connecting interrupted" <<< "$out" || fail "not the interrupted connect: $out"
echo "PASS: the lookup ended at its deadline and at Ctrl-C"
