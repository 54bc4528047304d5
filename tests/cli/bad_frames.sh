#!/usr/bin/env bash
# One bad frame never loses a whole run: a sequence whose frame 3 has a truncated depth file, frame
# 5 no annotated pose, frame 7 no mask and frame 9 a truncated colour file is tracked to the end;
# the three unreadable frames are reported lost with their reason and scored as failures, frame 5
# is tracked but not scored; with --strict the first bad file stops the run, naming it. An empty
# model (needed only for the scores) stops the run before any frame is tracked. bundletrack_eval
# scores a sequence without depth/ and masks/ as it scores the whole one, and scores lost frames
# as failures from the run's track.csv as bundletrack_track does, and with --in-view only the
# frames whose mask is not empty. A run that tracks nothing
# after the first frame prints no frame rate. An --out that cannot take the results (a file, a link
# loop, a place where no directory can be made, a name too long) and a directory where cam_K.txt
# belongs are refused, naming the cause, as are depth in other units than the scale says where the
# first pose tells (5 times too far) and a first pose beside the object. A run that stops leaves
# OUT/INCOMPLETE with the error; a finished one none.
# Usage: bad_frames.sh BUNDLETRACK_SYNTH BUNDLETRACK_TRACK BUNDLETRACK_EVAL WORK_DIR
set -euo pipefail
synth=$1 track=$2 eval=$3 work=$4
fail() { echo "FAILED: $*" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
"$synth" --out "$work/seq" --frames 12 > /dev/null
head -c 200 "$work/seq/depth/000003.png" > "$work/cut" && mv "$work/cut" "$work/seq/depth/000003.png"
rm "$work/seq/annotated_poses/000005.txt" "$work/seq/masks/000007.png"
head -c 200 "$work/seq/rgb/000009.png" > "$work/cut" && mv "$work/cut" "$work/seq/rgb/000009.png"

"$track" --sequence "$work/seq" --out "$work/out" --quiet > "$work/summary.txt" 2> "$work/stderr.txt" \
  || fail "exit status $? without --strict: $(cat "$work/stderr.txt")"
[ "$(ls "$work/out/poses" | wc -l)" -eq 12 ] || fail "not one pose per frame"
grep -q "12 frames, 3 lost" "$work/summary.txt" || fail "summary: $(head -1 "$work/summary.txt")"
grep -q "3 of the lost frames could not be read" "$work/summary.txt" || fail "no count of unreadable frames"
grep -q "1 frames without an annotated pose were not scored" "$work/summary.txt" || fail "no count of unscored frames"
# 11 frames scored, the 3 unreadable ones as missing estimates.
grep -Eq "^seq +[0-9.]+ +[0-9.]+ .* 11 +3$" "$work/summary.txt" || fail "score row: $(grep '^seq' "$work/summary.txt")"
# A second row scores the lost frames as failures.
grep -Eq "^seq \(lost=failed\) +[0-9.]+ +[0-9.]+ .* 11 +3$" "$work/summary.txt" || fail "no lost=failed row"
csv=$work/out/track.csv
row() { grep "^$1," "$csv"; }
row 000003 | grep -q ",lost,.*depth/000003.png: .*" || fail "frame 3: $(row 000003)"
row 000007 | grep -q ",lost,.*masks/000007.png: file not found" || fail "frame 7: $(row 000007)"
row 000009 | grep -q ",lost,.*rgb/000009.png: truncated or corrupt image" || fail "frame 9: $(row 000009)"
row 000005 | grep -q ",tracked,.*annotated_poses/000005.txt: file not found (frame not scored)" || fail "frame 5: $(row 000005)"
[ "$(grep -c ',lost,' "$csv")" -eq 3 ] || fail "lost frames in track.csv: $(grep -c ',lost,' "$csv")"
# A lost frame keeps the last good pose.
cmp -s "$work/out/poses/000002.txt" "$work/out/poses/000003.txt" || fail "frame 3 does not keep frame 2's pose"

if "$track" --sequence "$work/seq" --out "$work/strict" --quiet --strict > /dev/null 2> "$work/strict.txt"; then
  fail "--strict did not stop at the bad depth file"
fi
grep -q "depth/000003.png" "$work/strict.txt" || fail "--strict error: $(cat "$work/strict.txt")"
# The partial output of a run that stopped says so (OUT/INCOMPLETE, with the error); a finished run leaves none.
grep -q "stopped with an error" "$work/strict/INCOMPLETE" && grep -q "depth/000003.png" "$work/strict/INCOMPLETE" \
  || fail "no INCOMPLETE marker after --strict stopped: $(cat "$work/strict/INCOMPLETE" 2>&1)"
[ ! -e "$work/out/INCOMPLETE" ] || fail "a finished run left OUT/INCOMPLETE"

cp -r "$work/seq" "$work/truth_only" && rm -r "$work/truth_only/depth" "$work/truth_only/masks"
"$eval" --sequence "$work/seq" --poses "$work/out/poses" | sed -n 2p | cut -c25- > "$work/eval_whole.txt"
"$eval" --sequence "$work/truth_only" --poses "$work/out/poses" | sed -n 2p | cut -c25- > "$work/eval_truth_only.txt" \
  || fail "bundletrack_eval refused a sequence without depth/ and masks/"
[ -s "$work/eval_whole.txt" ] && cmp -s "$work/eval_whole.txt" "$work/eval_truth_only.txt" \
  || fail "scores differ: $(cat "$work/eval_whole.txt") / $(cat "$work/eval_truth_only.txt")"

# Nothing tracked after the first frame (the object carried out of view at once): no frame rate.
"$synth" --out "$work/gone" --frames 6 --out-of-view 1 5 > /dev/null
"$track" --sequence "$work/gone" --out "$work/gone_out" --quiet > "$work/gone.txt" || fail "out of view: exit $?"
grep -q "6 frames, 5 lost" "$work/gone.txt" || fail "out of view: $(head -1 "$work/gone.txt")"
grep -q "no frame after the first was tracked" "$work/gone.txt" || fail "out of view: no notice"
! grep -q "fps" "$work/gone.txt" || fail "a frame rate without a tracked frame: $(grep fps "$work/gone.txt")"
# bundletrack_eval reads the lost frames from the run's track.csv: its second table is the
# tracker's own "(lost=failed)" row; a track.csv without rows for the poses' frames is refused.
"$eval" --sequence "$work/gone" --poses "$work/gone_out/poses" > "$work/gone_eval.txt" || fail "eval of the lost run: exit $?"
grep -q "gone: 5 of the scored frames reported lost" "$work/gone_eval.txt" || fail "eval lost count: $(head -1 "$work/gone_eval.txt")"
grep "^gone (lost=failed)" "$work/gone.txt" | cut -c25- > "$work/lost_track.txt"
sed -n '/lost frames scored as failures/,$p' "$work/gone_eval.txt" | grep "^gone " | cut -c25- > "$work/lost_eval.txt"
[ -s "$work/lost_track.txt" ] && cmp -s "$work/lost_track.txt" "$work/lost_eval.txt" \
  || fail "lost=failed scores differ: $(cat "$work/lost_track.txt") / $(cat "$work/lost_eval.txt")"
# --in-view leaves out the frames whose mask is empty: the same rows as a copy of the sequence
# without the annotated poses of those frames (the object is out of view in frames 3-6 of 10).
"$synth" --out "$work/leaves" --frames 10 --out-of-view 3 4 > /dev/null
"$track" --sequence "$work/leaves" --out "$work/leaves_out" --quiet > /dev/null || fail "leaves the view: exit $?"
"$eval" --sequence "$work/leaves" --poses "$work/leaves_out/poses" --in-view > "$work/in_view.txt" || fail "--in-view: exit $?"
grep -q "4 frames with an empty mask (object out of view) were not scored" "$work/in_view.txt" \
  || fail "--in-view count: $(tail -1 "$work/in_view.txt")"
mv "$work/leaves" "$work/seen" && rm "$work/seen/annotated_poses/00000"[3-6].txt
"$eval" --sequence "$work/seen" --poses "$work/leaves_out/poses" | grep "^seen " | cut -c25- > "$work/seen_rows.txt"
grep "^leaves " "$work/in_view.txt" | cut -c25- > "$work/in_view_rows.txt"
grep -Eq " 6 +0$" "$work/in_view_rows.txt" && cmp -s "$work/seen_rows.txt" "$work/in_view_rows.txt" \
  || fail "--in-view scores differ: $(cat "$work/in_view_rows.txt") / $(cat "$work/seen_rows.txt")"
head -2 "$work/gone_out/track.csv" > "$work/cut.csv" && mv "$work/cut.csv" "$work/gone_out/track.csv"
if "$eval" --sequence "$work/gone" --poses "$work/gone_out/poses" > /dev/null 2> "$work/gone_eval_err.txt"; then
  fail "eval accepted a track.csv without rows for the poses"
fi
grep -q "track.csv: no row for frame 000001" "$work/gone_eval_err.txt" || fail "eval: $(cat "$work/gone_eval_err.txt")"

: > "$work/seq/model/points.xyz"
if "$track" --sequence "$work/seq" --out "$work/no_model" --quiet > /dev/null 2> "$work/no_model.txt"; then
  fail "an empty model/points.xyz was accepted"
fi
grep -q "model/points.xyz: no points" "$work/no_model.txt" || fail "empty model: $(cat "$work/no_model.txt")"
[ "$(ls "$work/no_model/poses" 2> /dev/null | wc -l)" -eq 0 ] || fail "frames were tracked before the model was read"

# Output that cannot be written is refused before any work, naming --out and the cause.
expect_error() {  # expect_error MESSAGE ARGS...: bundletrack_track exits 1 and says MESSAGE
  local message=$1; shift
  if "$track" "$@" --quiet > /dev/null 2> "$work/error.txt"; then fail "accepted: $*"; fi
  grep -q -- "$message" "$work/error.txt" || fail "$*: $(cat "$work/error.txt")"
}
cp "$work/out/track.csv" "$work/a_file"
expect_error "a_file: --out names a file, not a directory" --sequence "$work/gone" --out "$work/a_file"
ln -s "$work/loop_b" "$work/loop_a" && ln -s "$work/loop_a" "$work/loop_b"
expect_error "--out cannot be used: Too many levels of symbolic links" --sequence "$work/gone" --out "$work/loop_a"
expect_error "^error: /proc/bundletrack_out: --out: cannot create the directory" --sequence "$work/gone" --out /proc/bundletrack_out
long=$(printf 'x%.0s' $(seq 300))
expect_error "File name too long" --sequence "$work/gone" --out "$work/$long"
# Depth read 5 times too far (0.2 mm units taken for millimetres): a box 0.4 m away seems 1.8 m
# away, within any sensor's range, but its annotated first pose says 0.4 m: refused, naming the unit.
"$synth" --out "$work/near" --frames 2 --distance 0.4 > /dev/null
expect_error "000000: the start pose puts the object's origin at depth 0.400 m, the depth under its mask 1.79. m (4.4. times as far): the depth reads 5 times too far: depth.scale is probably 5 times too large" \
  --sequence "$work/near" --out "$work/near_out" --depth-scale 0.005
# A first pose 0.5 m beside the object (another frame's, or inverted): refused, not tracked from.
cp -r "$work/near" "$work/beside" && printf "1 0 0 0.5\n0 1 0 0\n0 0 1 0.4\n0 0 0 1\n" > "$work/beside/annotated_poses/000000.txt"
expect_error "000000: the start pose puts the object's origin .* degrees beside the object's mask" \
  --sequence "$work/beside" --out "$work/beside_out"
# A directory where a file belongs.
rm "$work/gone/cam_K.txt" && mkdir "$work/gone/cam_K.txt"
expect_error "cam_K.txt: is a directory, expected a file" --sequence "$work/gone" --out "$work/dir_k"
echo "bad frames: lost with their reasons, run completed; --strict stops at the first; an empty model stops it first; unusable --out and depth in other units refused first"
