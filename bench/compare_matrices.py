#!/usr/bin/python3
"""Stress-matrix runs of several settings side by side (e.g. the keypoint detectors of issue 16).

usage: compare_matrices.py LABEL=MATRIX_CSV [LABEL=MATRIX_CSV ...] > TABLE.md

Each MATRIX_CSV is the matrix.csv of one `bash bench/accuracy_matrix.sh BUILD OUT --config FILE`
run on the same sequences. Per cell: ADD-S, frames lost in view and the median tracking
milliseconds of each setting; per setting: the cells where its ADD-S is more than 0.5 below the
best setting's, and the median of its cells' times relative to the first setting's.
"""
import csv
import statistics
import sys

runs = [argument.split("=", 1) for argument in sys.argv[1:]]
if not runs or any(len(run) != 2 for run in runs):
    sys.exit(__doc__)
tables = {label: {row["cell"]: row for row in csv.DictReader(open(path))} for label, path in runs}
labels = [label for label, _ in runs]
cells = list(tables[labels[0]])


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


print("| cell | " + " | ".join(f"{label}: ADD-S | lost | ms" for label in labels) + " |")
print("|---|" + "---|---|---|" * len(labels))
below = {label: [] for label in labels}
time_ratios = {label: [] for label in labels}
for cell in cells:
    rows = [tables[label].get(cell) for label in labels]
    scores = [number(row["ADD-S"]) if row else None for row in rows]
    best = max(s for s in scores if s is not None)
    first_ms = number(rows[0]["ms_per_frame"]) if rows[0] else None
    line = f"| {cell} |"
    for label, row, score in zip(labels, rows, scores):
        if row is None or score is None:
            line += " n/a | | |"
            continue
        if score < best - 0.5:
            below[label].append(f"{cell} ({score - best:+.2f})")
        ms = number(row["ms_per_frame"])
        if ms and first_ms:
            time_ratios[label].append(ms / first_ms)
        line += f" {row['ADD-S']} | {row['lost_in_view']} | {row['ms_per_frame']} |"
    print(line)
print()
print("| setting | cells > 0.5 ADD-S below the best | median time / " + labels[0] + " |")
print("|---|---|---|")
for label in labels:
    ratio = statistics.median(time_ratios[label]) if time_ratios[label] else float("nan")
    print(f"| {label} | {len(below[label])}: {', '.join(below[label]) or '-'} | {ratio:.2f} |")
