#!/usr/bin/env bash
# Installs every dependency from Debian packages and builds sba-slam in Release.
# Usage: bash scripts/setup.sh [--no-build]
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libopencv-dev libeigen3-dev libceres-dev libcli11-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev
  python3 python3-numpy python3-torch python3-matplotlib python3-opencv
)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ "${1:-}" != "--no-build" ]; then
  # Extra configure flags (CI passes -DSBASLAM_WERROR=ON) come from SBASLAM_CMAKE_ARGS.
  # shellcheck disable=SC2086
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release ${SBASLAM_CMAKE_ARGS:-}
  cmake --build "$root/build" -j "$(nproc)"
fi
