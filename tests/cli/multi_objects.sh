#!/usr/bin/env bash
# bundletrack_track on a sequence of two objects (a folder of masks per object): each object's
# outputs in OUT/<object>/, a score row per object, --objects choosing one of them (whose poses
# are those of the run with both), unknown names and --objects on a one-object sequence refused
# with the reason; a missing mask of one object loses only that object's frame. The same sequence
# with label images instead of mask folders gives the same poses. With each object's first mask
# alone, the masks are propagated. A start pose beside an object delays that object's start.
# Usage: multi_objects.sh BUNDLETRACK_SYNTH BUNDLETRACK_TRACK WORK_DIR
set -euo pipefail
synth=$1 track=$2 work=$3
fail() { echo "FAILED: $*" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
"$synth" --out "$work/two" --objects 2 --frames 8 > /dev/null
rm "$work/two/masks/cylinder/000004.png"
"$track" --sequence "$work/two" --out "$work/both" --quiet > "$work/both.txt" 2> "$work/both_err.txt" \
  || fail "exit status $?: $(cat "$work/both_err.txt")"
for object in box cylinder; do
  [ "$(ls "$work/both/$object/poses" | wc -l)" -eq 8 ] || fail "$object: not one pose per frame"
  [ -s "$work/both/$object/track.csv" ] || fail "$object: no track.csv"
  grep -Eq "^$object +[0-9.]+ +[0-9.]+ " "$work/both.txt" || fail "no score row of $object: $(cat "$work/both.txt")"
done
grep -q "^\[box\] 8 frames, 0 lost" "$work/both.txt" || fail "box: $(grep '^\[box\]' "$work/both.txt")"
grep -q "^\[cylinder\] 8 frames, 1 lost" "$work/both.txt" || fail "cylinder: $(grep '^\[cylinder\]' "$work/both.txt")"
grep "^000004," "$work/both/cylinder/track.csv" | grep -q ",lost,.*masks/cylinder/000004.png: file not found" \
  || fail "cylinder frame 4: $(grep '^000004,' "$work/both/cylinder/track.csv")"
"$track" --sequence "$work/two" --out "$work/box" --objects box --quiet > /dev/null
diff -r "$work/box/box/poses" "$work/both/box/poses" > /dev/null || fail "box alone differs from box with the cylinder"
[ ! -e "$work/box/cylinder" ] || fail "--objects box wrote the cylinder's outputs"

if "$track" --sequence "$work/two" --out "$work/x" --objects box,plate 2> "$work/unknown.txt" > /dev/null; then
  fail "--objects with an unknown name was accepted"
fi
grep -q "no object 'plate' in .*masks (it has box, cylinder)" "$work/unknown.txt" || fail "unknown: $(head -1 "$work/unknown.txt")"
"$synth" --out "$work/one" --frames 2 > /dev/null
if "$track" --sequence "$work/one" --out "$work/y" --objects box 2> "$work/single.txt" > /dev/null; then
  fail "--objects on a one-object sequence was accepted"
fi
grep -q "holds the masks of one object" "$work/single.txt" || fail "single: $(head -1 "$work/single.txt")"
# Label images (labels/<frame>.png, labels/objects.txt) give each object the masks of its folder,
# so the same poses.
"$synth" --out "$work/two_labels" --objects 2 --frames 8 --labels > /dev/null
[ ! -e "$work/two_labels/masks" ] && [ -s "$work/two_labels/labels/000007.png" ] || fail "--labels wrote no label images"
"$track" --sequence "$work/two_labels" --out "$work/labels" --quiet --objects box > /dev/null
diff -r "$work/labels/box/poses" "$work/box/box/poses" > /dev/null || fail "poses from label images differ from those of the mask folders"
if "$track" --sequence "$work/two_labels" --out "$work/z" --objects plate 2> "$work/unknown_label.txt" > /dev/null; then
  fail "--objects with an unknown label name was accepted"
fi
grep -q "no object 'plate' in .*labels/objects.txt (it has box, cylinder)" "$work/unknown_label.txt" \
  || fail "unknown label: $(head -1 "$work/unknown_label.txt")"
# Each object's first mask only (the method's input), in mask folders or one label image: the masks
# are propagated from them, with a note, and no frame is lost for want of a mask.
cp -r "$work/two" "$work/two_first" && cp -r "$work/two_labels" "$work/labels_first"
find "$work/two_first/masks" "$work/labels_first/labels" -name '*.png' ! -name 000000.png -delete
for first in two_first labels_first; do
  "$track" --sequence "$work/$first" --out "$work/${first}_out" --quiet --no-score > /dev/null 2> "$work/$first.txt" ||
    fail "$first: exit status $?: $(cat "$work/$first.txt")"
  grep -q "each object has a mask for one frame only: the masks are propagated" "$work/$first.txt" ||
    fail "$first: no note that the masks are propagated: $(cat "$work/$first.txt")"
  for object in box cylinder; do
    [ "$(ls "$work/${first}_out/$object/masks" | wc -l)" -eq 8 ] || fail "$first: $object's propagated masks not written"
    if grep -q ",lost," "$work/${first}_out/$object/track.csv"; then
      fail "$first: $object's frames lost: $(grep ",lost," "$work/${first}_out/$object/track.csv")"
    fi
  done
done
# A start pose that the frame contradicts (here 0.5 m beside the cylinder) keeps that object from
# starting there, with the reason; it starts on the next frame, the other object is not touched.
# With --strict the run stops.
cp -r "$work/two" "$work/beside" && printf "1 0 0 0.5\n0 1 0 0\n0 0 1 0.7\n0 0 0 1\n" > "$work/beside/annotated_poses/cylinder/000000.txt"
"$track" --sequence "$work/beside" --out "$work/beside_out" > "$work/beside.txt" 2>&1 || fail "beside: exit $?: $(cat "$work/beside.txt")"
grep -q "frame 000000 cylinder not started: .* degrees beside the object's mask" "$work/beside.txt" || fail "beside: $(cat "$work/beside.txt")"
grep "^000000," "$work/beside_out/cylinder/track.csv" | grep -q "^000000,not_started,.*degrees beside" \
  || fail "beside: $(head -2 "$work/beside_out/cylinder/track.csv")"
/usr/bin/python3 -c 'import csv, sys; sys.exit(len({len(row) for row in csv.reader(open(sys.argv[1]))}) != 1)' \
  "$work/beside_out/cylinder/track.csv" || fail "beside: track.csv rows of different lengths: $(head -3 "$work/beside_out/cylinder/track.csv")"
grep -q "^\[cylinder\] 7 frames from frame 000001" "$work/beside.txt" || fail "beside: the cylinder did not start on frame 1"
diff -r "$work/beside_out/box/poses" "$work/both/box/poses" > /dev/null || fail "beside: the box's poses changed"
if "$track" --sequence "$work/beside" --out "$work/beside_strict" --strict --quiet > /dev/null 2>&1; then
  fail "--strict went on past a start pose beside the object"
fi
if "$synth" --out "$work/w" --labels 2> "$work/labels_one.txt" > /dev/null; then fail "--labels with one object was accepted"; fi
grep -q -- "--labels needs --objects 2 or 3" "$work/labels_one.txt" || fail "--labels alone: $(cat "$work/labels_one.txt")"
echo "multi-object command line: ok"
