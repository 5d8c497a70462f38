#!/usr/bin/env bash
# The Salient BA ablation of docs/RESULTS.md: uniform BA against Salient BA on the synthetic scenes
# and the real fixtures, alternating per seed, then per case the median ATE (and range) of each side,
# their ratio, a bootstrap interval for it and how often it meets the issue's target
# (python/ablation_stats.py).
#
# Usage: bash scripts/salient_ba_ablation.sh [--runs N] [--cases "cd cdm cl room eu k06"]
#            [--deterministic | --realtime] [--salient SPEC] [--set "Key: value"]... [--work DIR]
#   cases: cd / cdm  city-dynamic frames 0-249, stereo / monocular (ATE SE3 / Sim3)
#          cl        city-loop frames 0-299, stereo      room  room, 600 frames, stereo
#          eu        EuRoC V101 micro, stereo            k06   KITTI 06 first 51 frames, monocular
#   --salient: the Salient BA side's --saliency (default "model"; a folder of maps also works)
#   --deterministic: every run repeats exactly; the seed reaches only the RANSAC of monocular
#          initialisation and of relocalisation, so a stereo case then gives one run for every seed
#   --realtime: frames at the camera's rate, as ORB-SLAM3's examples feed them (the mapper then
#          skips keyframes it has no time for, so the result depends on the machine's speed)
#   --set: a settings line for both sides, replacing the key (e.g. --set "Saliency.saturation: 1")
# Renders the scenes into WORK (default /tmp/sba_ablation) once; about an hour for 10 runs of all
# six cases on a 2-core machine. Needs build/sba-slam and ../shared/data.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B="$root/build/sba-slam"
D="$root/../shared/data"
runs=10 cases="cd cdm cl room eu k06" mode="" salient="model" work=/tmp/sba_ablation
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --cases) cases="$2"; shift 2 ;;
    --deterministic) mode="--deterministic"; shift ;;
    --realtime) mode="--realtime"; shift ;;
    --salient) salient="$2"; shift 2 ;;
    --set) sets+=("$2"); shift 2 ;;
    --work) work="$2"; shift 2 ;;
    *) echo "salient_ba_ablation: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$B" ] || { echo "salient_ba_ablation: $B not built (bash scripts/setup.sh)" >&2; exit 1; }
[ -d "$D" ] || { echo "salient_ba_ablation: $D: no shared fixtures" >&2; exit 1; }
mkdir -p "$work"

render() {  # scene frames folder
  [ -f "$work/$3/settings.yaml" ] && return 0
  "$B" simulate --scene "$1" --frames "$2" --seed 1 --out "$work/$3" > /dev/null
}

# settings_for CASE -> the case's settings file with every --set line applied
settings_for() {
  local base out="$work/settings_$1.yaml"
  case "$1" in
    cd | cdm) base="$work/cd/settings.yaml" ;;
    cl) base="$work/cl/settings.yaml" ;;
    room) base="$work/room/settings.yaml" ;;
    eu) base="$root/config/EuRoC_stereo.yaml" ;;
    k06) base="$root/config/KITTI04-12.yaml" ;;
  esac
  cp "$base" "$out"
  for line in "${sets[@]+"${sets[@]}"}"; do
    grep -v "^${line%%:*}:" "$out" > "$out.tmp" || true
    mv "$out.tmp" "$out"
    echo "$line" >> "$out"
  done
  echo "$out"
}

# ate CASE OUT -> the ATE rmse of one run
ate() {
  local r
  case "$1" in
    cd | cdm)
      head -250 "$work/cd/poses/00.txt" > "$2/gt.txt"
      r=$("$B" eval ape "$2/gt.txt" "$2/trajectory.kitti" --format kitti \
            --align "$([ "$1" = cdm ] && echo sim3 || echo se3)") ;;
    cl)
      head -300 "$work/cl/poses/00.txt" > "$2/gt.txt"
      r=$("$B" eval ape "$2/gt.txt" "$2/trajectory.kitti" --format kitti --align se3) ;;
    room)
      r=$("$B" eval ape "$work/room/mav0/state_groundtruth_estimate0/data.csv" "$2/trajectory.tum" \
            --format euroc --align se3 --ref-body-to-cam "$work/room/mav0/cam0/sensor.yaml") ;;
    eu)
      r=$("$B" eval ape "$D/euroc_v101_micro/groundtruth/body_tum.txt" "$2/trajectory.tum" \
            --format tum --align se3 --ref-body-to-cam "$D/euroc_v101_micro/mav0/cam0/sensor.yaml") ;;
    k06)
      r=$("$B" eval ape "$work/k06_gt.tum" "$2/trajectory.tum" --format tum --align sim3) ;;
  esac
  echo "$r" | awk '$1 == "rmse" { print $2; exit }'
}

run_case() {  # CASE SOURCE SEED -> ATE
  local args out
  out="$work/runs/$1_$(basename "$2")_$3"
  case "$1" in
    cd) args=(--dataset kitti --path "$work/cd/sequences/00" --max-frames 250) ;;
    cdm) args=(--dataset kitti --path "$work/cd/sequences/00" --max-frames 250 --sensor mono) ;;
    cl) args=(--dataset kitti --path "$work/cl/sequences/00" --max-frames 300) ;;
    room) args=(--dataset euroc --path "$work/room" --sensor stereo) ;;
    eu) args=(--dataset euroc --path "$D/euroc_v101_micro" --sensor stereo) ;;
    k06) args=(--dataset kitti --path "$D/kitti06_first51/sequences/06" --sensor mono) ;;
  esac
  mkdir -p "$out"
  # shellcheck disable=SC2086
  "$B" run --settings "$(settings_for "$1")" "${args[@]}" --out "$out" --saliency "$2" \
    --seed "$3" $mode > "$out/log.txt" 2>&1 || { echo "run failed: $out/log.txt" >&2; exit 1; }
  ate "$1" "$out"
}

for c in $cases; do
  case "$c" in
    cd | cdm) render city-dynamic 250 cd ;;
    cl) render city-loop 300 cl ;;
    room) render room 600 room ;;
    eu | k06) ;;
    *) echo "salient_ba_ablation: unknown case '$c'" >&2; exit 2 ;;
  esac
done
[ -f "$work/k06_gt.tum" ] || "$B" convert "$D/kitti06_first51/poses/06.txt" "$work/k06_gt.tum" \
  --from kitti --to tum --times "$D/kitti06_first51/sequences/06/times.txt" > /dev/null

for c in $cases; do
  : > "$work/$c.none" ; : > "$work/$c.salient"
  for seed in $(seq 1 "$runs"); do
    run_case "$c" none "$seed" >> "$work/$c.none"
    run_case "$c" "$salient" "$seed" >> "$work/$c.salient"
  done
  # issue 7's targets: 0.5x on city-dynamic, 1.0x elsewhere
  target=1; case "$c" in cd | cdm) target=0.5 ;; esac
  printf '%-5s ' "$c"
  python3 "$root/python/ablation_stats.py" "$work/$c.none" "$work/$c.salient" --target "$target"
done
