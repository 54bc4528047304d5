#!/usr/bin/env bash
# The stress matrix (issue 15): synthetic sequences with exact ground truth over distance, object,
# texture, speed and sensor, plus the shared real sequences where present, tracked with the
# default settings. Per cell: ADD, ADD-S, mean rotation error, lost frames (all, those while
# the object is in view, and those while the depth camera also read some of it), median tracking
# time, and ADD / ADD-S over the frames in view only (bundletrack_eval --in-view; they differ
# where the object leaves the view). With --before, a
# second build's tracker runs on the very same sequences and its columns stand beside.
#
# The design is sparse (62 synthetic cells, not the 144 of the full product), chosen so that each
# factor varies with the others held at their usual value:
#   A  distance {0.5, 1, 2, 3 m} x object {mug 0.10 m, box 0.20 m, chair 0.70 m} x {textured,
#      textureless}, structured light, normal speed (no chair at 0.5 m: it would not fit the view);
#   B  sensor {active stereo, time of flight} x distance {1, 3 m} x object, textured;
#   C  fast motion (3x) x {box, mug} x {1, 2 m}, textured; at 1 m also with the colour averaged over
#      8 instants of the exposure (bundletrack_synth --motion-blur 8), as a hand-held camera blurs;
#   D  an occluder (box, 1 m) and the object carried out of view and back (box at 1 m; textureless
#      chair at 2.5 m).
#   E  masks that err from the object's outline by 3 px, as a segmentation's or a depth-to-colour
#      registration's do (bundletrack_synth --mask-error): grown, shrunk and moved on the box at 1 m,
#      grown and moved on the textureless box at 3 m, grown on the mug at 1 m.
#   F  the method's own input, the first frame's mask alone (bundletrack_track --propagate-masks):
#      the box at 1 m, the textureless mug at 1 m, the textureless box and chair at 3 m, the
#      textureless chair at 2.5 m under active stereo, the box behind the occluder at 2 m, the mug
#      at 3 m; and the shared sequences (real_*_propagated).
#   G  other image sizes and fields of view (bundletrack_synth --resolution, --focal), 1280x720: 87
#      degrees wide (focal 674 px, a RealSense D435's depth at 720p) with the box at 1 m under active
#      stereo, 93 degrees (605 px, an Azure Kinect's 720p colour camera, depth mapped to it) with the
#      textureless chair at 3 m under time of flight, and the 640x480 camera's 56 degrees at twice
#      its pixels (1200 px) with the mug at 1 m.
#   H  a time-of-flight camera's flying pixels (bundletrack_synth --flying-pixels 1: every depth-edge
#      pixel that keeps a reading mixes the two surfaces' depths): box and mug at 1 m, textureless
#      chair at 3 m.
# The shared real sequences are tracked as they are, from their first mask alone, and derived as
# held-out data may differ from them (bench/real_variants.py): at half and a third of their pixels
# (the object 2.2 and 3.3 m away in pixel terms, with the depth noise of its true 1.1 m) and every
# third frame (three times the motion between frames).
#
# Usage: bash bench/accuracy_matrix.sh BUILD_DIR OUT_DIR [--before BUILD_DIR [--before-label TEXT]]
#        [--config FILE] [--data DIR] [--frames N] [--only REGEX] [--markdown FILE]
# (--config: YAML settings for the BUILD_DIR tracker instead of the defaults, e.g. another
# features.type; the --before tracker always runs with its defaults. --only: the cells whose
# names match the extended regular expression, e.g. those a change can touch.)
# (BUILD_DIR: a build tree or a folder holding bundletrack_track.) Sequences are generated once
# into OUT_DIR/sequences; the --before runs are kept in OUT_DIR/runs/before and reused.
# Mug cells also get the rotation error split by whether the handle is visible, with the visible
# frames after it was first hidden for 10 frames apart (bench/mug_rotation.py; issue 15 scores the
# mug's rotation where the handle is visible). Writes OUT_DIR/matrix.csv, OUT_DIR/mug_rotation.csv
# and the Markdown tables (default OUT_DIR/ACCURACY.md; the committed bench/ACCURACY.md is made
# with --markdown bench/ACCURACY.md).
set -euo pipefail
build=${1:?build directory}
out=${2:?output directory}
shift 2
before="" before_label="the --before build" config="" only="" data="$(dirname "$0")/../../shared/data/7scenes_objects" frames=100 markdown=""
while [ $# -gt 0 ]; do
  case "$1" in
    --before) before=$2; shift 2 ;;
    --before-label) before_label=$2; shift 2 ;;
    --config) config=$(realpath "$2"); shift 2 ;;
    --data) data=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --markdown) markdown=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
markdown=${markdown:-$out/ACCURACY.md}
mkdir -p "$out/sequences"
py=/usr/bin/python3

cells=()
size_of() { case $1 in mug) echo 0.10 ;; box) echo 0.20 ;; chair) echo 0.70 ;; esac; }
for d in 0.5 1 2 3; do
  for o in mug box chair; do
    [ "$o" = chair ] && [ "$d" = 0.5 ] && continue
    for t in textured textureless; do
      opts="--shape $o --size $(size_of $o) --distance $d"
      [ "$t" = textureless ] && opts+=" --textureless"
      cells+=("A_${o}_${d}m_${t}|$opts")
    done
  done
done
for s in active_stereo time_of_flight; do
  for d in 1 3; do
    for o in mug box chair; do cells+=("B_${o}_${d}m_${s}|--shape $o --size $(size_of $o) --distance $d --sensor $s"); done
  done
done
for o in box mug; do
  for d in 1 2; do cells+=("C_${o}_${d}m_fast|--shape $o --size $(size_of $o) --distance $d --speed 3"); done
  cells+=("C_${o}_1m_fast_blur8|--shape $o --size $(size_of $o) --distance 1 --speed 3 --motion-blur 8")
done
cells+=("D_box_1m_occluder|--shape box --distance 1 --occluder")
cells+=("D_box_1m_out_of_view|--shape box --distance 1 --out-of-view 40 15")
cells+=("D_chair_2.5m_textureless_out_of_view|--shape chair --size 0.70 --distance 2.5 --textureless --out-of-view 40 15")
for e in dilate erode shift; do cells+=("E_box_1m_mask_${e}3|--shape box --size 0.20 --distance 1 --mask-error $e --mask-error-px 3"); done
for e in dilate shift; do
  cells+=("E_box_3m_textureless_mask_${e}3|--shape box --size 0.20 --distance 3 --textureless --mask-error $e --mask-error-px 3")
done
cells+=("E_mug_1m_mask_dilate3|--shape mug --size 0.10 --distance 1 --mask-error dilate --mask-error-px 3")
for cell in "box_1m|--shape box --size 0.20 --distance 1" "mug_1m_textureless|--shape mug --size 0.10 --distance 1 --textureless" \
  "box_3m_textureless|--shape box --size 0.20 --distance 3 --textureless" \
  "chair_3m_textureless|--shape chair --size 0.70 --distance 3 --textureless" \
  "chair_2.5m_textureless_active_stereo|--shape chair --size 0.70 --distance 2.5 --textureless --sensor active_stereo" \
  "box_2m_occluder|--shape box --size 0.20 --distance 2 --occluder" "mug_3m|--shape mug --size 0.10 --distance 3"; do
  cells+=("F_${cell%%|*}_propagated|${cell#*|}|--propagate-masks")
done
cells+=("G_box_1m_active_stereo_720p|--shape box --size 0.20 --distance 1 --sensor active_stereo --resolution 1280x720 --focal 674")
cells+=("G_chair_3m_textureless_time_of_flight_720p|--shape chair --size 0.70 --distance 3 --textureless --sensor time_of_flight --resolution 1280x720 --focal 605")
cells+=("G_mug_1m_720p|--shape mug --size 0.10 --distance 1 --resolution 1280x720")
cells+=("H_box_1m_time_of_flight_flying_pixels|--shape box --size 0.20 --distance 1 --sensor time_of_flight --flying-pixels 1")
cells+=("H_mug_1m_time_of_flight_flying_pixels|--shape mug --size 0.10 --distance 1 --sensor time_of_flight --flying-pixels 1")
cells+=("H_chair_3m_textureless_time_of_flight_flying_pixels|--shape chair --size 0.70 --distance 3 --textureless --sensor time_of_flight --flying-pixels 1")

tool() {  # build name -> path of the build's executable
  if [ -x "$1/bin/$2" ]; then echo "$1/bin/$2"; else echo "$1/$2"; fi
}
track() {  # build sequence target [reuse [config [tracker options]]] -> csv fields
  local bin seq=$2 target=$3 reuse=${4:-} settings=()
  bin=$(tool "$1" bundletrack_track)
  [ -n "${5:-}" ] && settings=(--config "$5")
  # shellcheck disable=SC2206
  [ -n "${6:-}" ] && settings+=($6)
  mkdir -p "$target"
  if [ -z "$reuse" ] || ! grep -q "^sequence" "$target.log" 2> /dev/null; then
    "$bin" --sequence "$seq" --out "$target" --quiet "${settings[@]}" > "$target.log" 2>&1 || { echo "n/a,n/a,n/a,n/a,n/a,n/a,n/a,n/a,n/a"; return; }
  fi
  # Scored by this build's bundletrack_eval also for the --before runs: scoring does not change with the tracker.
  "$(tool "$build" bundletrack_eval)" --sequence "$seq" --poses "$target/poses" --in-view --json "$target.in_view.json" > /dev/null ||
    rm -f "$target.in_view.json"
  $py - "$seq" "$target" <<'PY'
import csv, json, pathlib, sys
import cv2
seq, target = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
log = (target.parent / (target.name + ".log")).read_text().splitlines()
header = next(i for i, line in enumerate(log) if line.startswith("sequence"))
fields = log[header + 1].split()
add, adds, r_err = fields[1], fields[2], fields[5].replace("dg", "")
rows = list(csv.DictReader(open(target / "track.csv")))
lost = [r for r in rows if r["status"] == "lost"]
def true_mask(frame):
    path = seq / "masks" / (frame + ".png")
    return cv2.imread(str(path), cv2.IMREAD_GRAYSCALE) if path.exists() else None
def in_view(frame):
    mask = true_mask(frame)
    return mask is not None and cv2.countNonZero(mask) > 0
def with_depth(frame):  # the depth camera read some of what the colour camera sees of the object
    mask, depth = true_mask(frame), cv2.imread(str(seq / "depth" / (frame + ".png")), cv2.IMREAD_UNCHANGED)
    return mask is not None and depth is not None and bool(((mask > 0) & (depth > 0)).any())
lost_in_view = sum(in_view(r["frame"]) for r in lost)
lost_with_depth = sum(with_depth(r["frame"]) for r in lost)
times = sorted(float(r["total_ms"]) for r in rows[1:])
in_view_json = target.parent / (target.name + ".in_view.json")
in_view_score = json.load(open(in_view_json))["sequences"][0] if in_view_json.exists() else {"ADD": None, "ADD_S": None}
in_view = ",".join("n/a" if v is None else f"{v:.2f}" for v in (in_view_score["ADD"], in_view_score["ADD_S"]))
print(f"{add},{adds},{r_err},{len(lost)},{lost_in_view},{lost_with_depth},{times[len(times) // 2]:.1f},{in_view}")
PY
}

csv_file="$out/matrix.csv"
run_columns="ADD,ADD-S,R_err_deg,lost,lost_in_view,lost_with_depth,ms_per_frame,ADD_in_view,ADD-S_in_view"
echo "cell,options,$run_columns,before_${run_columns//,/,before_}" > "$csv_file"
mug_csv="$out/mug_rotation.csv"
mug_columns="visible_frames,R_err_visible_deg,hidden_frames,R_err_hidden_deg,again_frames,R_err_again_deg"
echo "cell,$mug_columns,before_${mug_columns//,/,before_}" > "$mug_csv"
selected() { [ -z "$only" ] || [[ $1 =~ $only ]]; }
run_cell() {  # name options sequence [tracker options]
  local name=$1 options=$2 seq=$3 tracking=${4:-} after before_fields=",,,,,,,," mug_before=",,,,,"
  after=$(track "$build" "$seq" "$out/runs/after/$name" "" "$config" "$tracking")
  [ -n "$before" ] && before_fields=$(track "$before" "$seq" "$out/runs/before/$name" reuse "" "$tracking")
  [ -n "$tracking" ] && options+="; tracked with $tracking"
  echo "$name,\"$options\",$after,$before_fields" >> "$csv_file"
  echo "$name: $after | before: $before_fields"
  if [[ $name == *_mug_* && $name != real_* ]]; then
    [ -n "$before" ] && mug_before=$($py "$(dirname "$0")/mug_rotation.py" "$seq" "$out/runs/before/$name")
    echo "$name,$($py "$(dirname "$0")/mug_rotation.py" "$seq" "$out/runs/after/$name"),$mug_before" >> "$mug_csv"
  fi
}
for cell in "${cells[@]}"; do
  name=${cell%%|*}
  options=${cell#*|}
  tracking=""
  [[ $options == *"|"* ]] && tracking=${options#*|} && options=${options%%|*}
  selected "$name" || continue
  seq="$out/sequences/$name"
  # shellcheck disable=SC2086
  [ -d "$seq/rgb" ] || "$(tool "$build" bundletrack_synth)" --out "$seq" --frames "$frames" $options > /dev/null
  run_cell "$name" "$options" "$seq" "$tracking"
done
for s in mug_1 magazines_1 container_1; do
  [ -d "$data/$s" ] && selected "real_$s" && run_cell "real_$s" "shared sequence" "$data/$s"
done
for s in mug_1 magazines_1 container_1; do
  [ -d "$data/$s" ] && selected "real_${s}_propagated" && run_cell "real_${s}_propagated" "shared sequence" "$data/$s" --propagate-masks
done
for s in mug_1 magazines_1 container_1; do
  [ -d "$data/$s" ] || continue
  for variant in "half_pixels|--scale 0.5|at half its pixels" "third_pixels|--scale 0.3333333|at a third of its pixels" \
    "every_3rd_frame|--every 3|every third frame"; do
    IFS='|' read -r suffix derive what <<< "$variant"
    selected "real_${s}_$suffix" || continue
    seq="$out/sequences/real_${s}_$suffix"
    # shellcheck disable=SC2086
    [ -d "$seq/rgb" ] || $py "$(dirname "$0")/real_variants.py" "$data/$s" "$seq" $derive
    run_cell "real_${s}_$suffix" "shared sequence $what (real_variants.py $derive)" "$seq"
  done
done

$py - "$csv_file" "$markdown" "$frames" "$mug_csv" "$([ -n "$before" ] && echo 1 || echo 0)" "$before_label" "$config" "$only" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
frames, mug_rows = sys.argv[3], list(csv.DictReader(open(sys.argv[4])))
with_before, before_label = sys.argv[5] == "1", sys.argv[6]
settings = f"settings of {sys.argv[7]}" if sys.argv[7] else "default settings"
out = ["# Accuracy stress matrix", "",
       f"Generated by `bash bench/accuracy_matrix.sh` (synthetic cells: {frames} frames each, exact ground truth;",
       f"{settings}). ADD and ADD-S: AUC in % (0-10 cm); R_err: mean rotation error in degrees;",
       "lost: frames reported lost (in view: while the object's true mask is not empty; with depth: while",
       "the depth camera also read some of it, where a nearer object's shadow left none on it); ms: median",
       "tracking time per frame on this machine (2 cores); in view: ADD / ADD-S over the frames in which",
       "the object is seen (`bundletrack_eval --in-view`), which differ from the whole sequence's only",
       "where the object leaves the view (D_*_out_of_view). Cell names: A distance x object x texture,",
       "B sensor, C fast motion, D occlusion and out of view, E masks 3 px off the outline, F and",
       "real_*_propagated: the first frame's mask alone (--propagate-masks), G 1280x720 images at",
       "other fields of view, H a time-of-flight camera's flying pixels; real_*_half_pixels,",
       "real_*_third_pixels, real_*_every_3rd_frame: the shared sequences as held-out data may differ",
       "(bench/real_variants.py: the object 2.2 / 3.3 m away in pixel terms with its own depth noise,",
       "three times the motion); see the script's header for the design."]
if with_before:
    out.append(f"The before columns: {before_label}, on the same sequences.")
if sys.argv[8]:
    out.append(f"Only the cells whose names match `{sys.argv[8]}` (`--only`).")
out.append("")


def table(columns, before_columns, rows, row_cells, before_cells):
    """A Markdown table of rows, with the before columns beside when there are any."""
    head = "| " + " | ".join(columns) + " |"
    rule = "|" + "---|" * len(columns)
    if with_before:
        head += " before: " + " | ".join(before_columns) + " |"
        rule += "---|" * len(before_columns)
    lines = [head, rule]
    for r in rows:
        line = "| " + " | ".join(row_cells(r)) + " |"
        if with_before:
            line += " " + " | ".join(before_cells(r)) + " |"
        lines.append(line)
    return lines


def run_cells(prefix):
    return lambda r: [r[prefix + "ADD"], r[prefix + "ADD-S"], r[prefix + "R_err_deg"],
                      f"{r[prefix + 'lost']} ({r[prefix + 'lost_in_view']} / {r[prefix + 'lost_with_depth']})", r[prefix + "ms_per_frame"],
                      f"{r[prefix + 'ADD_in_view']} / {r[prefix + 'ADD-S_in_view']}"]


out += table(["cell", "options", "ADD", "ADD-S", "R_err", "lost (in view / with depth)", "ms", "in view: ADD / ADD-S"],
             ["ADD", "ADD-S", "R_err", "lost (in view / with depth)", "ms", "in view: ADD / ADD-S"], rows,
             lambda r: [r["cell"], r["options"]] + run_cells("")(r), run_cells("before_"))
out += ["", "## The mug's rotation where its handle is visible", "",
        "A mug's body is a surface of revolution: with the handle hidden, only texture constrains the",
        "rotation about its axis. Mean rotation error (degrees) over the frames where a quarter of the",
        "handle's model points are seen (bench/mug_rotation.py), and over the others; target < 5 where",
        "the handle is visible. Of the visible frames, those after the handle was first hidden for 10",
        "frames in a row stand apart (\"again\"): the mug turns on while its handle is hidden, and without",
        "texture that turn is in no frame's data, so there the tracker must find the handle again rather",
        "than hold it.", ""]
out += table(["cell", "handle visible: frames", "R_err", "of them, again: frames", "R_err", "hidden: frames", "R_err"],
             ["visible R_err", "again R_err", "hidden R_err"], mug_rows,
             lambda r: [r["cell"], r["visible_frames"], r["R_err_visible_deg"], r["again_frames"], r["R_err_again_deg"],
                        r["hidden_frames"], r["R_err_hidden_deg"]],
             lambda r: [r["before_R_err_visible_deg"], r["before_R_err_again_deg"], r["before_R_err_hidden_deg"]])
open(sys.argv[2], "w").write("\n".join(out) + "\n")
PY
echo "wrote $csv_file, $mug_csv and $markdown"
