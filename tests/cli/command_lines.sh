#!/usr/bin/env bash
# The programs' command lines (CLI11, examples/command_line.hpp): --help prints every option and
# exits 0; a command line they refuse exits 2 with "error:" naming the option and what was wrong,
# and nothing is written; a well-formed one runs. bundletrack_track's numbers are checked by the
# settings table (its range and unit), its choices by their names.
# Usage: command_lines.sh BUNDLETRACK_SYNTH BUNDLETRACK_TRACK BUNDLETRACK_EVAL BUNDLETRACK_INSPECT WORK_DIR
set -euo pipefail
synth=$1 track=$2 eval=$3 inspect=$4 work=$5
fail() { echo "FAILED: $*" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"

# --help: exit 0, every option listed.
"$synth" --help > "$work/help.txt" || fail "bundletrack_synth --help: exit $?"
for option in --out --frames --shape --size --distance --sensor --resolution --focal --flying-pixels --out-of-view --objects --labels --seed --layout; do
  grep -q -- "$option" "$work/help.txt" || fail "bundletrack_synth --help does not list $option"
done
"$track" --help > "$work/help.txt" || fail "bundletrack_track --help: exit $?"
for option in --sequence --out --config --features --min-inliers --sensor --propagate-masks --strict --objects --quiet --no-score; do
  grep -q -- "$option" "$work/help.txt" || fail "bundletrack_track --help does not list $option"
done
"$eval" --help | grep -q -- "--in-view" || fail "bundletrack_eval --help does not list --in-view"
"$inspect" -h | grep -q -- "--every" || fail "bundletrack_inspect -h does not list --every"

# refused <expected stderr text> <program> <arguments...>: exit 2, the text on stderr, no output written.
refused() {
  local expected=$1
  shift
  set +e
  "$@" > /dev/null 2> "$work/stderr.txt"
  local status=$?
  set -e
  [ "$status" -eq 2 ] || fail "$* exited $status, not 2: $(cat "$work/stderr.txt")"
  grep -qF -- "$expected" "$work/stderr.txt" || fail "$*: expected '$expected' in: $(cat "$work/stderr.txt")"
  grep -q "^error: " "$work/stderr.txt" || fail "$*: no 'error:' line"
  [ ! -e "$work/never" ] || fail "$* wrote its output"
}
refused "--frames: expects a whole number >= 1, got '2.5'" "$synth" --out "$work/never" --frames 2.5
refused "--frames: expects a whole number >= 1, got 'ten'" "$synth" --out "$work/never" --frames ten
refused "--distance: expects a number > 0, got '-2'" "$synth" --out "$work/never" --distance -2
refused "--objects: expects a whole number in [1, 3], got '4'" "$synth" --out "$work/never" --objects 4
refused "--shape: cone not in {box,cylinder,mug,chair}" "$synth" --out "$work/never" --shape cone
refused "--out-of-view" "$synth" --out "$work/never" --out-of-view 5
refused "--frames" "$synth" --out "$work/never" --frames 3 --frames 4
refused "--colour" "$synth" --out "$work/never" --colour red
refused "--out is required" "$synth" --frames 3
refused "--labels needs --objects 2 or 3" "$synth" --out "$work/never" --labels
refused "--resolution 1280x: expected WIDTHxHEIGHT in pixels" "$synth" --out "$work/never" --resolution 1280x
refused "--resolution 1280x720x3: expected WIDTHxHEIGHT" "$synth" --out "$work/never" --resolution 1280x720x3
refused "--resolution 32x24: expected WIDTHxHEIGHT in pixels, each from 64 to 8192" "$synth" --out "$work/never" --resolution 32x24
refused "--focal: expects a number > 0, got '0'" "$synth" --out "$work/never" --focal 0
refused "--flying-pixels: expects a number in [0, 1], got '1.5'" "$synth" --out "$work/never" --flying-pixels 1.5

# --resolution and --focal: the images' size (a PNG's IHDR holds width and height at bytes 16-23)
# and cam_K.txt's intrinsics, the principal point at the centre.
"$synth" --out "$work/small" --frames 1 --resolution 320x200 --focal 250 > /dev/null || fail "bundletrack_synth --resolution failed"
for image in rgb/000000.png depth/000000.png masks/000000.png; do
  size=$(od -An -tu1 -j16 -N8 "$work/small/$image" | awk '{print $3 * 256 + $4 "x" $7 * 256 + $8}')
  [ "$size" = 320x200 ] || fail "$image is $size, not 320x200"
done
[ "$(tr -s ' \n' ' ' < "$work/small/cam_K.txt" | sed 's/ $//')" = "250 0 159.5 0 250 99.5 0 0 1" ] ||
  fail "cam_K.txt of --resolution 320x200 --focal 250: $(cat "$work/small/cam_K.txt")"

"$synth" --out "$work/seq" --frames 3 --shape mug --distance 0.8 > /dev/null || fail "a well-formed bundletrack_synth command line failed"
refused "--sequence and --out are required" "$track" --sequence "$work/seq"
refused "--features" "$track" --sequence "$work/seq" --out "$work/never" --features orb --features sift
refused "--sensor 'lidar': expected structured_light | active_stereo | time_of_flight" \
  "$track" --sequence "$work/seq" --out "$work/never" --sensor lidar
refused "--inlier-mm expects a number, got '5mm'" "$track" --sequence "$work/seq" --out "$work/never" --inlier-mm 5mm
refused "--speed" "$track" --sequence "$work/seq" --out "$work/never" --speed 2
refused "give one --poses for every --sequence" "$eval" --sequence "$work/seq" --sequence "$work/seq" --poses "$work/seq"
refused "--every: expects a whole number >= 1, got '0'" "$inspect" --sequence "$work/seq" --every 0

"$track" --sequence "$work/seq" --out "$work/out" --quiet --features orb --min-inliers 6 > "$work/summary.txt" ||
  fail "a well-formed bundletrack_track command line failed"
[ "$(ls "$work/out/poses" | wc -l)" -eq 3 ] || fail "not one pose per frame"
grep -q "ADD-S" "$work/summary.txt" || fail "no score table for a sequence with ground truth"
"$track" --sequence "$work/seq" --out "$work/unscored" --quiet --no-score > "$work/unscored.txt" ||
  fail "bundletrack_track --no-score failed"
if grep -q "ADD-S" "$work/unscored.txt"; then fail "--no-score still printed the score table"; fi
[ "$(ls "$work/unscored/poses" | wc -l)" -eq 3 ] || fail "--no-score: not one pose per frame"
# A sequence with the first frame's mask only (the method's input): the masks are propagated from it,
# with a note, and every frame is tracked, not lost for want of a mask.
cp -r "$work/seq" "$work/first_mask" && rm "$work/first_mask/masks/000001.png" "$work/first_mask/masks/000002.png"
"$track" --sequence "$work/first_mask" --out "$work/first_mask_out" --quiet --no-score > /dev/null 2> "$work/first_mask.txt" ||
  fail "bundletrack_track on a sequence with only its first mask failed: $(cat "$work/first_mask.txt")"
grep -q "mask for the first frame only: the masks are propagated" "$work/first_mask.txt" ||
  fail "no note that the masks are propagated: $(cat "$work/first_mask.txt")"
[ "$(ls "$work/first_mask_out/masks" | wc -l)" -eq 3 ] || fail "first mask only: the propagated masks are not written"
if grep -q ",lost," "$work/first_mask_out/track.csv"; then fail "first mask only: frames lost: $(cat "$work/first_mask_out/track.csv")"; fi
echo "command lines: help, refusals and well-formed runs as expected"
