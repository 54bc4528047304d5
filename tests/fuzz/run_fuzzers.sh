#!/usr/bin/env bash
# Builds the libFuzzer targets of this folder with clang (address and undefined-behaviour
# sanitizers on) and runs each for SECONDS on seeds made here: the synthetic generator's files
# (cam_K.txt, a pose, model points, colour / depth / mask PNGs, a label list and image) and the
# tracker's printed configuration. A crash, a sanitizer report or an exception other than InputError fails the test
# and leaves the input under WORK_DIR/crashes. Exits 77 (ctest: skipped) without a clang that links
# -fsanitize=fuzzer.
# Usage: run_fuzzers.sh BUNDLETRACK_SYNTH BUNDLETRACK_TRACK WORK_DIR SECONDS
set -euo pipefail
synth=$1 track=$2 work=$3 seconds=$4
here=$(cd "$(dirname "$0")" && pwd)
clang=$(command -v clang++ || true)
if [ -z "$clang" ]; then echo "SKIPPED: no clang++ (apt-get install clang)"; exit 77; fi
rm -rf "$work" && mkdir -p "$work/crashes"
printf '#include <cstddef>\n#include <cstdint>\nextern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n' > "$work/probe.cpp"
if ! "$clang" -fsanitize=fuzzer "$work/probe.cpp" -o "$work/probe" 2> "$work/probe.txt"; then
  echo "SKIPPED: $clang cannot link -fsanitize=fuzzer: $(head -1 "$work/probe.txt")"; exit 77
fi
cmake -S "$here" -B "$work/build" -DCMAKE_CXX_COMPILER="$clang" -DCMAKE_BUILD_TYPE=None > "$work/configure.txt" \
  || { cat "$work/configure.txt"; exit 1; }
cmake --build "$work/build" -j2 > "$work/build.txt" || { tail -30 "$work/build.txt"; exit 1; }

# Seeds: the first byte says what the rest is read as (fuzz_sequence_files.cpp).
"$synth" --out "$work/seq" --frames 1 > /dev/null
mkdir -p "$work/seeds/sequence" "$work/seeds/config"
seed() { { printf '%s' "$1"; cat "$2"; } > "$work/seeds/sequence/$1_$(basename "$2")"; }
seed 0 "$work/seq/cam_K.txt"
seed 1 "$work/seq/annotated_poses/000000.txt"
head -50 "$work/seq/model/points.xyz" > "$work/points.xyz" && seed 2 "$work/points.xyz"
seed 3 "$work/seq/rgb/000000.png"
seed 4 "$work/seq/depth/000000.png"
seed 5 "$work/seq/masks/000000.png"
printf '# label object\n1 box\n2 cylinder\n' > "$work/objects.txt" && seed 6 "$work/objects.txt"
seed 7 "$work/seq/masks/000000.png"
"$track" --print-config > "$work/seeds/config/defaults.yaml"
printf 'features:\n  type: orb\n  detect: every_frame\ndepth:\n  min_depth: 0.2\n' > "$work/seeds/config/some.yaml"

status=0
for target in fuzz_sequence_files fuzz_config; do
  corpus=$work/corpus/$target && mkdir -p "$corpus"
  seeds=$work/seeds/$([ $target = fuzz_config ] && echo config || echo sequence)
  echo "== $target: $seconds s"
  if ! "$work/build/$target" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=65536 \
       -artifact_prefix="$work/crashes/$target-" -print_final_stats=1 "$corpus" "$seeds" > "$work/$target.log" 2>&1; then
    tail -40 "$work/$target.log"; status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$work/$target.log" | tail -2
  fi
done
exit $status
