#!/usr/bin/env bash
# Installs every Debian 12 package that building, running and testing bellows needs.
# As root it runs apt-get; otherwise it prints the exact command to run.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libncurses-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libboost-dev
  liblcm-dev liblcm-bin libglib2.0-dev libmatio-dev libmodbus-dev libsodium-dev
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev clang-format clang-tidy
  tmux rt-tests iproute2 util-linux ccache ninja-build
  gnuplot-nox fonts-dejavu-core python3-scipy python3-pandas octave help2man
)

missing=()
for p in "${packages[@]}"; do
  [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" = "install ok installed" ] || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
command="apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "bellows needs these packages: ${missing[*]}" >&2
  echo "run as root:  $command" >&2
  exit 1
fi
echo "installing: ${missing[*]}" >&2
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
