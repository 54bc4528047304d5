#!/usr/bin/python3
"""A shared real sequence as the held-out data may show it (issue 15): farther, or faster.

  real_variants.py SEQUENCE OUT --scale S   the same frames at S times the pixels (S = 1/3: a
                                            640x480 camera's object 3x as far in pixel terms)
  real_variants.py SEQUENCE OUT --every K   every K-th frame (the object moves K times as far
                                            between frames)

Scaling keeps the depth readings themselves (nearest pixel: a depth camera of fewer pixels reads
points, it does not average across edges) and so the depth noise of the near object: it tests what
depends on the object's size in pixels (grid step, keypoints, masks, optical flow), not the
noise model, which the synthetic matrix covers. Colour is averaged over each new pixel (as a
sensor's pixel integrates light) and written as JPEG at quality 95; masks by nearest pixel. The
intrinsics follow the pixel-centre convention: u' = (u + 0.5) S - 0.5. Ground truth, the model
and the layout (YCBInEOAT) are those of the source.
"""
import argparse
import pathlib
import shutil

import cv2
import numpy as np


def scaled(source: pathlib.Path, out: pathlib.Path, scale: float) -> None:
    for folder, interpolation in (("rgb", cv2.INTER_AREA), ("depth", cv2.INTER_NEAREST), ("masks", cv2.INTER_NEAREST)):
        (out / folder).mkdir(parents=True, exist_ok=True)
        for path in sorted((source / folder).iterdir()):
            image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
            if image is None:
                raise SystemExit(f"error: {path}: not an image")
            image = cv2.resize(image, None, fx=scale, fy=scale, interpolation=interpolation)
            params = [cv2.IMWRITE_JPEG_QUALITY, 95] if path.suffix.lower() in (".jpg", ".jpeg") else []
            cv2.imwrite(str(out / folder / path.name), image, params)
    K = np.loadtxt(source / "cam_K.txt")
    K[0, 0] *= scale
    K[1, 1] *= scale
    K[:2, 2] = (K[:2, 2] + 0.5) * scale - 0.5
    np.savetxt(out / "cam_K.txt", K, fmt="%.6f")
    shutil.copytree(source / "annotated_poses", out / "annotated_poses", dirs_exist_ok=True)
    shutil.copytree(source / "model", out / "model", dirs_exist_ok=True)


def every(source: pathlib.Path, out: pathlib.Path, step: int) -> None:
    for folder in ("rgb", "depth", "masks", "annotated_poses"):
        (out / folder).mkdir(parents=True, exist_ok=True)
        for index, path in enumerate(sorted((source / folder).iterdir())[::step]):
            shutil.copyfile(path, out / folder / f"{index:06d}{path.suffix}")
    shutil.copyfile(source / "cam_K.txt", out / "cam_K.txt")
    shutil.copytree(source / "model", out / "model", dirs_exist_ok=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequence", type=pathlib.Path)
    parser.add_argument("out", type=pathlib.Path)
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("--scale", type=float)
    kind.add_argument("--every", type=int)
    args = parser.parse_args()
    if args.scale is not None and not 0 < args.scale <= 1:
        parser.error("--scale must lie in (0, 1]")
    if args.every is not None and args.every < 1:
        parser.error("--every must be at least 1")
    if not (args.sequence / "cam_K.txt").is_file():
        parser.error(f"{args.sequence}: no cam_K.txt (not a YCBInEOAT sequence)")
    if args.scale is not None:
        scaled(args.sequence, args.out, args.scale)
    else:
        every(args.sequence, args.out, args.every)


if __name__ == "__main__":
    main()
