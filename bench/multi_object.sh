#!/usr/bin/env bash
# Several objects per camera (issue 17): one synthetic sequence of three objects (box, can, mug,
# each carried by its own hand, passing in front of each other), tracked in one sitting with one,
# two and three of them (--objects box; box,cylinder; all) and with each object alone. Per run:
# the median milliseconds per frame of tracking (all objects of the frame), of the whole run from
# the files to the poses, and each object's ADD / ADD-S, which must not depend on how many objects
# share the frames. Then what each added object costs: the whole run's growth when it joins,
# against the whole run of that object alone (issue 17's target: at most 0.5).
# Usage: bash bench/multi_object.sh BUILD_DIR OUT_DIR [FRAMES]
set -euo pipefail
build=${1:?build directory} out=${2:?output directory} frames=${3:-150}
bin=$build/bin
[ -x "$bin/bundletrack_track" ] || bin=$build
mkdir -p "$out"
[ -d "$out/three" ] || "$bin/bundletrack_synth" --out "$out/three" --objects 3 --frames "$frames" > /dev/null
declare -A whole_of
echo "| objects | tracking ms / frame (median) | whole run ms / frame | box ADD / ADD-S | cylinder ADD / ADD-S | mug ADD / ADD-S |"
echo "|---|---|---|---|---|---|"
for objects in box box,cylinder all cylinder mug; do
  run=$out/run_${objects//,/_}
  rm -rf "$run"
  "$bin/bundletrack_track" --sequence "$out/three" --out "$run" --objects "$objects" --quiet > "$run.txt"
  tracking=$(sed -n 's/^median per frame: \([0-9.]*\) ms tracking.*/\1/p' "$run.txt")
  whole=$(sed -n 's/^whole run after the first frame: \([0-9.]*\) ms.*/\1/p' "$run.txt")
  whole_of[$objects]=$whole
  row="| $objects | $tracking | $whole"
  for object in box cylinder mug; do
    score=$(awk -v o="$object" '$1 == o { printf "%s / %s", $2, $3 }' "$run.txt")
    row="$row | ${score:--}"
  done
  echo "$row |"
done
echo
echo "| object added | to | whole run grows by (ms / frame) | the object alone (ms / frame) | ratio |"
echo "|---|---|---|---|---|"
awk -v a="${whole_of[box]}" -v b="${whole_of[box,cylinder]}" -v c="${whole_of[all]}" \
    -v cyl="${whole_of[cylinder]}" -v mug="${whole_of[mug]}" 'BEGIN {
  printf "| cylinder | box | %.1f | %.1f | %.2f |\n", b - a, cyl, (b - a) / cyl
  printf "| mug | box, cylinder | %.1f | %.1f | %.2f |\n", c - b, mug, (c - b) / mug
}'
