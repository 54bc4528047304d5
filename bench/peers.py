#!/usr/bin/python3
"""Peer comparison: bundletrack against Open3D's frame-to-frame registration, same data, one run.

usage: /usr/bin/python3 bench/peers.py --build BUILD_DIR --out DIR [--before BUILD_DIR --before-label TEXT]
                                      SEQUENCE_DIR [SEQUENCE_DIR ...]

Every method starts from the annotated first pose, sees each frame's given mask, and chains
frame-to-frame estimates (no re-initialisation). Open3D methods, on the masked object:
  icp_point_to_plane  point-to-plane ICP of frame t onto frame t-1 (5 mm voxels, 2 cm gate)
  icp_colored         coloured ICP (Park et al. 2017), same clouds and gate
  rgbd_odometry       Open3D RGB-D odometry (Steinbruecker et al. 2011 with the hybrid
                      photometric + depth term of Park et al.) on the masked depth
Time per frame counts everything from the image files to the pose (decoding included) for every
method: for Open3D the loop over the frames after the first in this process (interpreter start
and imports not counted), for ours the whole bundletrack_track process (start, initialisation on
the first frame, writing the poses, track.csv and model.ply) divided by the number of frames,
run with --no-score (the ADD / ADD-S table at its end is evaluation, not tracking; every method is
scored by bundletrack_eval below) where the binary has it. With --before, a second build's
bundletrack_track runs the same way in the same run (a build without --no-score: its scoring
counted, as the table's note says). The row "decoding only" is the
time OpenCV takes to decode the same files (colour, depth, mask), the floor of any method reading
them. Poses are scored by bundletrack_eval (ADD and ADD-S AUC on [0, 10 cm], 5deg5cm), so every
method goes through the same evaluation.
Needs the Debian packages python3-open3d, python3-opencv and python3-numpy.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

import cv2
import numpy as np
import open3d as o3d

VOXEL = 0.005  # metres: the tracker's dense grid samples the object at about this spacing at 1 m
GATE = 0.02  # metres: the tracker's edge gate; frame-to-frame motion stays well inside it
DEPTH_MAX = 3.0  # metres


def read_matrix(path):
    return np.loadtxt(path).reshape(4, 4)


def write_pose(path, pose):
    np.savetxt(path, pose, fmt="%.9f")


class Sequence:
    def __init__(self, root):
        self.root = root
        self.names = sorted(os.path.splitext(f)[0] for f in os.listdir(os.path.join(root, "rgb")))
        self.K = np.loadtxt(os.path.join(root, "cam_K.txt")).reshape(3, 3)
        self.first_pose = read_matrix(os.path.join(root, "annotated_poses", self.names[0] + ".txt"))

    def image(self, folder, name, flags):
        for ext in (".png", ".jpg"):
            path = os.path.join(self.root, folder, name + ext)
            if os.path.exists(path):
                image = cv2.imread(path, flags)
                if image is None:
                    raise SystemExit(f"error: {path}: cannot decode image")
                return image
        raise SystemExit(f"error: {os.path.join(self.root, folder, name)}.png: file not found")

    def frame(self, name):
        """Colour (RGB), depth in metres with zeros outside the mask."""
        color = cv2.cvtColor(self.image("rgb", name, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
        depth = self.image("depth", name, cv2.IMREAD_UNCHANGED).astype(np.float32) * 1e-3
        mask = self.image("masks", name, cv2.IMREAD_GRAYSCALE) > 0
        depth[~mask] = 0.0
        return color, depth


def intrinsic(sequence, color):
    h, w = color.shape[:2]
    K = sequence.K
    return o3d.camera.PinholeCameraIntrinsic(w, h, K[0, 0], K[1, 1], K[0, 2], K[1, 2])


def rgbd(color, depth, intensity=False):
    """Odometry works on intensity, coloured ICP on colour."""
    return o3d.geometry.RGBDImage.create_from_color_and_depth(
        o3d.geometry.Image(color), o3d.geometry.Image(depth), depth_scale=1.0, depth_trunc=DEPTH_MAX,
        convert_rgb_to_intensity=intensity)


def cloud(color, depth, camera):
    points = o3d.geometry.PointCloud.create_from_rgbd_image(rgbd(color, depth), camera)
    points = points.voxel_down_sample(VOXEL)
    points.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2 * VOXEL, max_nn=30))
    points.orient_normals_towards_camera_location(np.zeros(3))
    return points


def icp(source, target, colored):
    criteria = o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=30)
    if len(source.points) < 3 or len(target.points) < 3:
        return None
    if colored:
        result = o3d.pipelines.registration.registration_colored_icp(
            source, target, GATE, np.eye(4), o3d.pipelines.registration.TransformationEstimationForColoredICP(), criteria)
    else:
        result = o3d.pipelines.registration.registration_icp(
            source, target, GATE, np.eye(4), o3d.pipelines.registration.TransformationEstimationPointToPlane(), criteria)
    return result.transformation if result.fitness > 0 else None


def run_open3d(sequence, method, out):
    """Chains T_cam_obj(t) = T_{t-1,t}^-1 T_cam_obj(t-1); a failed step keeps the last pose."""
    os.makedirs(os.path.join(out, "poses"), exist_ok=True)
    pose = sequence.first_pose
    previous = None
    times, failures = [], 0
    option = o3d.pipelines.odometry.OdometryOption()
    jacobian = o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm()
    for i, name in enumerate(sequence.names):
        start = time.perf_counter()
        color, depth = sequence.frame(name)
        camera = intrinsic(sequence, color)
        if method == "rgbd_odometry":
            current = rgbd(color, depth, intensity=True)
            step = None
            if previous is not None:
                ok, T, _ = o3d.pipelines.odometry.compute_rgbd_odometry(current, previous, camera, np.eye(4), jacobian, option)
                step = T if ok else None
        else:
            current = cloud(color, depth, camera)
            step = icp(current, previous, method == "icp_colored") if previous is not None else None
        if previous is not None:
            if step is None:
                failures += 1
            else:
                pose = np.linalg.inv(step) @ pose  # step maps frame t into frame t-1
        previous = current
        write_pose(os.path.join(out, "poses", name + ".txt"), pose)
        if i > 0:
            times.append(1e3 * (time.perf_counter() - start))
    return statistics.mean(times), failures


def decode_only(sequence):
    """Milliseconds per frame to decode the colour, depth and mask files, frames after the first."""
    start = time.perf_counter()
    for name in sequence.names[1:]:
        sequence.frame(name)
        sequence.image("masks", name, cv2.IMREAD_GRAYSCALE)
    return 1e3 * (time.perf_counter() - start) / (len(sequence.names) - 1)


def has_no_score(binary):
    """Whether this bundletrack_track can leave out its final score table (--no-score)."""
    return "--no-score" in subprocess.run([binary, "--help"], check=True, capture_output=True, text=True).stdout


def run_ours(build, sequence, out):
    binary = os.path.join(build, "bin", "bundletrack_track")
    if not os.path.exists(binary):
        binary = os.path.join(build, "bundletrack_track")
    command = [binary, "--sequence", sequence.root, "--out", out, "--quiet"]
    if has_no_score(binary):
        command.append("--no-score")
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    ms = 1e3 * (time.perf_counter() - start) / len(sequence.names)
    with open(os.path.join(out, "track.csv")) as f:
        rows = list(csv.DictReader(f))[1:]
    return ms, sum(r["status"] == "lost" for r in rows)


def score(build, sequence, poses, json_path):
    subprocess.run([os.path.join(build, "bin", "bundletrack_eval"), "--sequence", sequence.root, "--poses", poses,
                    "--json", json_path], check=True, stdout=subprocess.DEVNULL)
    with open(json_path) as f:
        return json.load(f)["sequences"][0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="build/peers")
    parser.add_argument("--before", help="a second build (or folder with bundletrack_track) run beside ours")
    parser.add_argument("--before-label", default="before")
    parser.add_argument("sequences", nargs="+")
    parser.add_argument("--methods", default="bundletrack,icp_point_to_plane,icp_colored,rgbd_odometry",
                        help="comma-separated subset; bundletrack must be one (the time ratios refer to it)")
    args = parser.parse_args()
    methods = args.methods.split(",")
    if "bundletrack" not in methods:
        parser.error("--methods must include bundletrack")
    before = f"bundletrack ({args.before_label})"
    if args.before:
        methods.insert(methods.index("bundletrack") + 1, before)
    print("| sequence | method | ADD AUC | ADD-S AUC | 5deg5cm | ms per frame | ours / method time | failed steps |")
    print("|---|---|---|---|---|---|---|---|")
    for root in args.sequences:
        sequence = Sequence(os.path.normpath(root))
        name = os.path.basename(sequence.root)
        results = {}
        for method in methods:
            out = os.path.join(args.out, name, method)
            if method == "bundletrack":
                ms, failures = run_ours(args.build, sequence, out)
            elif method == before:
                out = os.path.join(args.out, name, "bundletrack_before")
                ms, failures = run_ours(args.before, sequence, out)
            else:
                ms, failures = run_open3d(sequence, method, out)
            results[method] = (score(args.build, sequence, os.path.join(out, "poses"), os.path.join(out, "score.json")),
                               ms, failures)
        ours_ms = results["bundletrack"][1]
        for method in methods:
            s, ms, failures = results[method]
            print(f"| {name} | {method} | {s['ADD']:.1f} | {s['ADD_S']:.1f} | {s['deg5cm5']:.1f}% | {ms:.1f} | "
                  f"{ours_ms / ms:.2f} | {failures} |")
        decode_ms = decode_only(sequence)
        print(f"| {name} | decoding only (OpenCV) | | | | {decode_ms:.1f} | {ours_ms / decode_ms:.2f} | |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
