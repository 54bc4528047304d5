#!/usr/bin/env bash
# Tracks every CLI configuration (given / propagated masks, sift / orb / akaze, coarse) on the
# README's default synthetic sequence and on the shared real sequences, and writes the poses to
# OUT/<config>/<sequence>/poses. Compare two such runs with bench/compare_poses.py.
# Usage: bash bench/pose_regression.sh BUILD_DIR OUT_DIR [DATA_DIR]
set -euo pipefail
build=${1:?build directory}
out=${2:?output directory}
data=${3:-$(dirname "$0")/../../shared/data/7scenes_objects}
mkdir -p "$out"
synthetic="$out/synthetic_box"
[ -d "$synthetic/rgb" ] || "$build/bin/bundletrack_synth" --out "$synthetic" > /dev/null
sequences=("$synthetic")
for s in mug_1 magazines_1 container_1; do [ -d "$data/$s" ] && sequences+=("$data/$s"); done
configs=("sift:" "propagated:--propagate-masks" "orb:--features orb" "akaze:--features akaze" "coarse:--tracker coarse")
for entry in "${configs[@]}"; do
  name=${entry%%:*}
  options=${entry#*:}
  for sequence in "${sequences[@]}"; do
    target="$out/$name/$(basename "$sequence")"
    mkdir -p "$target"
    # shellcheck disable=SC2086
    "$build/bin/bundletrack_track" --sequence "$sequence" --out "$target" --quiet $options > "$target.log" 2>&1
    echo "$name $(basename "$sequence"): $(grep -o '[0-9]* lost' "$target.log" | head -1)"
  done
done
