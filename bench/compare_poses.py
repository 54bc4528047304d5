#!/usr/bin/python3
"""Largest element difference between the pose files of two bench/pose_regression.sh runs.

Usage: /usr/bin/python3 bench/compare_poses.py REFERENCE_DIR CANDIDATE_DIR [--tolerance 1e-6]
Prints one row per configuration and sequence; exits 1 when a pose is missing or differs by more
than the tolerance.
"""
import argparse
import pathlib
import sys

import numpy as np


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("reference", type=pathlib.Path)
    parser.add_argument("candidate", type=pathlib.Path)
    parser.add_argument("--tolerance", type=float, default=1e-6)
    args = parser.parse_args()
    failed = False
    rows = sorted(p.parent for p in args.reference.glob("*/*/poses"))
    if not rows:
        sys.exit(f"{args.reference}: no <config>/<sequence>/poses folders")
    print(f"| configuration | sequence | frames | max element difference |\n|---|---|---|---|")
    for run in rows:
        relative = run.relative_to(args.reference)
        worst, frames = 0.0, 0
        for reference in sorted((run / "poses").glob("*.txt")):
            candidate = args.candidate / relative / "poses" / reference.name
            if not candidate.exists():
                print(f"{candidate}: missing", file=sys.stderr)
                failed = True
                continue
            worst = max(worst, float(np.abs(np.loadtxt(reference) - np.loadtxt(candidate)).max()))
            frames += 1
        failed |= worst > args.tolerance
        print(f"| {relative.parent} | {relative.name} | {frames} | {worst:.3g} |")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
