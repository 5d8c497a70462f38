#!/usr/bin/env bash
# Trains the ORB vocabulary that loop closing ships (models/orb_vocabulary.bin): renders three
# synthetic sequences with seeds no test or benchmark uses (other worlds than theirs), then
# clusters the ORB descriptors of every 5th frame of them and of the real KITTI 06 and EuRoC
# fixtures into a 10-way, 4-level tree (about 10,000 words).
#
# Usage: bash scripts/train_vocabulary.sh [--work DIR] [--out FILE]
# Renders into WORK (default /tmp/sba_vocabulary) once (about 5 minutes on 2 cores); training
# takes under a minute. Needs build/sba-slam and ../shared/data.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B="$root/build/sba-slam"
D="$root/../shared/data"
work=/tmp/sba_vocabulary out="$root/models/orb_vocabulary.bin"
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "train_vocabulary: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$B" ] || { echo "train_vocabulary: $B not built (bash scripts/setup.sh)" >&2; exit 1; }
[ -d "$D" ] || { echo "train_vocabulary: $D: no shared fixtures" >&2; exit 1; }

render() {  # scene seed folder
  [ -f "$work/$3/scene.json" ] || "$B" simulate --scene "$1" --seed "$2" --out "$work/$3"
}
render city-loop 901 city_loop
render city-dynamic 902 city_dynamic
render room 903 room

"$B" vocabulary train --branching 10 --levels 4 --seed 0 --out "$out" \
  --every 5 --images "$work/city_loop/sequences/00/image_0" \
  --images "$work/city_dynamic/sequences/00/image_0" \
  --images "$work/room/mav0/cam0/data" \
  --images "$D/kitti06_first51/sequences/06/image_0" \
  --images "$D/euroc_v101_micro/mav0/cam0/data"
