"""The Python module against the command-line tracker on the same synthetic sequence, against
numpy references for the metrics, and every bad argument. Run by ctest (python_module), which
sets PYTHONPATH to the built module and BUNDLETRACK_BIN to the programs."""
import os
import pathlib
import subprocess

import cv2
import numpy as np
import pytest

import bundletrack as bt

BIN = pathlib.Path(os.environ["BUNDLETRACK_BIN"])
FRAMES = 30


def run(program, *args):
    subprocess.run([str(BIN / program), *map(str, args)], check=True, stdout=subprocess.DEVNULL)


@pytest.fixture(scope="session")
def box(tmp_path_factory):
    """The default synthetic box (exact ground truth), and the CLI's poses on it."""
    root = tmp_path_factory.mktemp("box")
    run("bundletrack_synth", "--out", root / "seq", "--frames", FRAMES)
    run("bundletrack_track", "--sequence", root / "seq", "--out", root / "given", "--quiet")
    run("bundletrack_track", "--sequence", root / "seq", "--out", root / "propagated", "--quiet", "--propagate-masks")
    run("bundletrack_synth", "--out", root / "tum", "--frames", FRAMES, "--layout", "tum")
    run("bundletrack_track", "--sequence", root / "tum", "--out", root / "tum_track", "--quiet")
    return root


def cli_poses(root, run_name):
    return [np.loadtxt(p) for p in sorted((root / run_name / "poses").glob("*.txt"))]


def files(seq, i):
    """Frame i as OpenCV reads the files: BGR uint8, depth uint16 millimetres, mask uint8."""
    name = f"{i:06d}.png"
    return (cv2.imread(str(seq / "rgb" / name), cv2.IMREAD_COLOR),
            cv2.imread(str(seq / "depth" / name), cv2.IMREAD_UNCHANGED),
            cv2.imread(str(seq / "masks" / name), cv2.IMREAD_UNCHANGED))


def start_pose(seq, name):
    """The first frame's pose as the CLI reads it, from its file's numbers. ground_truth(0) is that
    pose's matrix after its rotation was normalised, 1e-16 away, and so small a difference can tip a
    later dense association across a pixel's edge: one frame of the propagated run then differs by
    3e-9 (a graph that stops at 0.1 mm steps does not run on until it converges it away)."""
    return np.loadtxt(seq / "annotated_poses" / f"{name}.txt")


def track_files(seq, config=None, masks=True, tracker=None):
    sequence = bt.Sequence(str(seq))
    tracker = tracker or bt.Tracker(config)
    poses = []
    for i in range(len(sequence)):
        rgb, depth, mask = files(seq, i)
        if i == 0:
            result = tracker.initialize(rgb, depth, mask, sequence.K, start_pose(seq, sequence.names[0]))
        else:
            result = tracker.track(rgb, depth, mask if masks else None)
        poses.append(result.pose)
    return poses


def read_ply(path):
    lines = path.read_text().splitlines()
    body = lines[lines.index("end_header") + 1:]
    return np.array([list(map(float, line.split())) for line in body])


def largest_difference(a, b):
    assert len(a) == len(b) == FRAMES
    return max(np.abs(x - y).max() for x, y in zip(a, b))


def test_numpy_frames_give_the_cli_poses(box):
    # The CLI writes 10 decimals; the same computation differs by at most their rounding.
    assert largest_difference(track_files(box / "seq"), cli_poses(box, "given")) <= 1e-9


def test_object_model_equals_the_cli_model_and_lies_on_the_box(box, tmp_path):
    tracker = bt.Tracker()
    track_files(box / "seq", tracker=tracker)
    model = tracker.object_model()
    points, normals, colors = model["points"], model["normals"], model["colors"]
    assert points.shape == normals.shape == colors.shape and points.dtype == np.float32 and colors.dtype == np.uint8
    cli = read_ply(box / "given" / "model.ply")  # x y z nx ny nz red green blue
    assert cli.shape == (len(points), 9)
    assert np.abs(cli[:, :3] - points).max() < 1e-6  # PLY's printed digits
    assert np.array_equal(cli[:, 6:9], colors[:, ::-1])
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    tracker.write_model(tmp_path / "model.ply")
    assert (tmp_path / "model.ply").read_text() == (box / "given" / "model.ply").read_text()
    # Against the true surface's samples: within a few sensor spreads (1.4 mm at 0.73 m).
    truth = bt.Sequence(str(box / "seq")).model_points()
    nearest = np.sqrt(((points[:, None, :] - truth[None, :, :]) ** 2).sum(axis=2).min(axis=1))
    assert np.median(nearest) < 0.01  # the samples are ~7 mm apart: this bounds sampling, not noise


def test_propagated_masks_give_the_cli_poses(box):
    poses = track_files(box / "seq", {"masks": {"source": "propagated"}}, masks=False)
    assert largest_difference(poses, cli_poses(box, "propagated")) <= 1e-9


def test_sequence_reader_float_metres_give_the_same_poses(box):
    sequence = bt.Sequence(str(box / "seq"))
    assert len(sequence) == FRAMES and sequence.names[0] == "000000"
    tracker = bt.Tracker({})
    poses = []
    for i in range(len(sequence)):
        rgb, depth, mask = sequence.read(i)
        assert depth.dtype == np.float32 and rgb.shape == (480, 640, 3)
        result = (tracker.initialize(rgb, depth, mask, sequence.K, start_pose(box / "seq", sequence.names[0])) if i == 0
                  else tracker.track(rgb, depth, mask))
        poses.append(result.pose)
    assert largest_difference(poses, cli_poses(box, "given")) <= 1e-9
    assert tracker.frames == FRAMES and tracker.keyframes >= 1


def test_tum_layout_through_numpy_gives_the_cli_poses_and_the_truth(box):
    sequence = bt.Sequence(box / "tum")  # rgb.txt, depth.txt: found by itself
    assert sequence.names[1] == "1305031102.033333"
    tracker = bt.Tracker()
    poses = []
    for i in range(len(sequence)):
        rgb, depth, mask = sequence.read(i)
        result = (tracker.initialize(rgb, depth, mask, sequence.K, start_pose(box / "tum", sequence.names[0])) if i == 0
                  else tracker.track(rgb, depth, mask))
        poses.append(result.pose)
    cli = [np.loadtxt(box / "tum_track" / "poses" / f"{name}.txt") for name in sequence.names]
    assert largest_difference(poses, cli) <= 1e-9
    score = bt.score(sequence.model_points(), [sequence.ground_truth(i) for i in range(FRAMES)], poses)
    assert score["adds_auc"] > 95.0  # mean error under 5 mm: the depth read in the right unit


def test_result_fields(box):
    seq = box / "seq"
    sequence = bt.Sequence(str(seq))
    tracker = bt.Tracker()
    first = tracker.initialize(*files(seq, 0), sequence.K)
    assert np.array_equal(first.pose, np.eye(4))  # no pose given: the identity
    result = tracker.track(*files(seq, 1))
    assert result.status == "tracked" and result.tracked
    assert first.stability is None  # the first frame has no graph
    assert isinstance(result.stability, float) and 0.0 < result.stability <= 1.0
    assert result.pose.shape == (4, 4) and result.pose.dtype == np.float64
    assert set(result.timings) == {"mask", "features", "matching", "ransac", "graph", "solve", "total"}
    assert result.mask.shape == (480, 640) and set(np.unique(result.mask)) <= {0, 255}
    assert "tracked" in repr(result)


def test_scores_equal_a_numpy_reference(box):
    sequence = bt.Sequence(str(box / "seq"))
    model = sequence.model_points().astype(np.float64)
    truth = [sequence.ground_truth(i) for i in range(FRAMES)]
    estimates = cli_poses(box, "given")
    estimates[5] = None  # a frame without an estimate: a failure

    def add(t, e):
        return np.linalg.norm(model @ t[:3, :3].T + t[:3, 3] - (model @ e[:3, :3].T + e[:3, 3]), axis=1).mean()

    def auc(errors, top=0.1):  # VOCap of the YCB-Video toolbox: accuracy k/n from the k-th smallest error on
        e = np.sort(np.asarray(errors))
        e = e[e <= top]
        steps = np.diff(np.concatenate([[0.0], e, [top]]))
        return 100.0 * np.sum(steps * np.arange(1, len(e) + 2).clip(max=len(e)) / len(errors)) / top

    errors = [add(t, e) if e is not None else np.inf for t, e in zip(truth, estimates)]
    score = bt.score(model, truth, estimates)
    assert score["frames"] == FRAMES and score["missing"] == 1
    # The library sums float32 points (6e-9 m on a 0.1 m coordinate); the AUC moves 1000 per metre.
    assert score["add_auc"] == pytest.approx(auc(errors), abs=2e-5)
    present = [(t, e) for t, e in zip(truth, estimates) if e is not None]
    def angle(t, e):  # of the relative rotation, from its sine and cosine (arccos alone is ill-conditioned near 0)
        r = t[:3, :3].T @ e[:3, :3]
        sine = np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2
        return np.degrees(np.arctan2(sine, (np.trace(r) - 1) / 2))

    rotation = [angle(t, e) for t, e in present]
    assert score["rotation_error_deg"] == pytest.approx(np.mean(rotation), abs=1e-6)
    assert bt.rotation_error_deg(truth[3], estimates[3]) == pytest.approx(rotation[3], abs=1e-6)
    assert bt.translation_error(truth[3], estimates[3]) == pytest.approx(np.linalg.norm(truth[3][:3, 3] - estimates[3][:3, 3]))


def test_config_from_a_dict_a_file_and_their_errors(box, tmp_path):
    assert "type: orb" in bt.Tracker({"features": {"type": "orb"}}).config_yaml
    assert "inlier_distance: 0.004" in bt.Tracker({"ransac": {"inlier_distance": np.float32(0.004).item()}}).config_yaml
    yaml = tmp_path / "orb.yaml"
    yaml.write_text("features:\n  type: orb\n")
    assert bt.Tracker(str(yaml)).config_yaml == bt.Tracker({"features": {"type": "orb"}}).config_yaml
    assert bt.Tracker(yaml).config_yaml == bt.Tracker(str(yaml)).config_yaml  # os.PathLike
    with pytest.raises(ValueError, match="unknown key 'features.kind'"):
        bt.Tracker({"features": {"kind": "orb"}})
    with pytest.raises(ValueError, match=r"features.type = 'surf': expected sift \| orb \| akaze"):
        bt.Tracker({"features": {"type": "surf"}})
    with pytest.raises(ValueError, match=r"ransac.min_inliers = 2 is out of range"):
        bt.Tracker({"ransac": {"min_inliers": 2}})
    with pytest.raises(ValueError, match="must be a whole number"):
        bt.Tracker({"ransac": {"min_inliers": 5.5}})
    with pytest.raises(ValueError, match="is not below depth.max_depth"):
        bt.Tracker({"depth": {"min_depth": 3.0, "max_depth": 2.0}})
    with pytest.raises(ValueError, match="file not found"):
        bt.Tracker(str(tmp_path / "missing.yaml"))
    with pytest.raises(TypeError, match="section 'features' must be a dict"):
        bt.Tracker({"features": "orb"})
    with pytest.raises(TypeError, match="not a bool"):
        bt.Tracker({"features": {"max_keypoints": True}})
    with pytest.raises(TypeError, match="expected a dict of sections"):
        bt.Tracker(["features"])


def bad_argument_cases():
    """(what is wrong, arguments to initialize or track, exception, message)."""
    rgb = np.zeros((480, 640, 3), np.uint8)
    depth = np.full((480, 640), 700, np.uint16)
    mask = np.zeros((480, 640), np.uint8)
    mask[200:260, 300:360] = 255
    K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
    good = dict(rgb=rgb, depth=depth, mask=mask, K=K)
    init = [
        ("rgb float64", dict(good, rgb=rgb.astype(np.float64)), TypeError, "rgb: expected dtype uint8"),
        ("rgb grey", dict(good, rgb=rgb[:, :, 0]), ValueError, r"rgb: expected an HxWx3 BGR image, got shape \(480, 640\)"),
        ("rgb a list", dict(good, rgb=[[0]]), TypeError, "rgb: expected a numpy array, got list"),
        ("depth int32", dict(good, depth=depth.astype(np.int32)), TypeError, "depth: expected dtype uint16"),
        ("depth float64", dict(good, depth=depth.astype(np.float64)), TypeError, "or float32 .metres., got float64"),
        ("depth another size", dict(good, depth=depth[:240]), ValueError, r"depth: expected an HxW array .*got shape \(240, 640\)"),
        ("depth in metres as uint16", dict(good, depth=np.ones((480, 640), np.uint16)), ValueError, "depth scale is probably too small"),
        ("depth all zero", dict(good, depth=np.zeros((480, 640), np.uint16)), ValueError, "no valid depth under the first frame's object mask"),
        ("mask float", dict(good, mask=mask.astype(np.float32)), TypeError, "mask: expected dtype bool or uint8"),
        ("mask another size", dict(good, mask=mask[:, :320]), ValueError, "mask: expected an HxW array"),
        ("mask empty", dict(good, mask=np.zeros_like(mask)), ValueError, "mask: the first frame's object mask is empty"),
        ("mask missing", dict(good, mask=None), ValueError, "mask: the first frame needs the object's mask"),
        ("K 2x2", dict(good, K=np.eye(2)), ValueError, r"K: expected a 3x3 matrix, got shape \(2, 2\)"),
        ("K a string", dict(good, K="K"), TypeError, "K: expected a 3x3 matrix of numbers"),
        ("K negative focal", dict(good, K=K * [[-1, 1, 1], [1, 1, 1], [1, 1, 1]]), ValueError, "focal lengths"),
        ("K in other units", dict(good, K=K * [[1e4, 1, 1], [1, 1e4, 1], [1, 1, 1]]), ValueError, "field of view"),
        ("K NaN", dict(good, K=K * np.nan), ValueError, "non-finite"),
        ("pose not rigid", dict(good, pose=np.diag([2.0, 1, 1, 1])), ValueError, "pose: rotation block is not a rotation"),
        ("pose 3x4", dict(good, pose=np.eye(4)[:3]), ValueError, r"pose: expected a 4x4 matrix, got shape \(3, 4\)"),
        ("pose last row", dict(good, pose=np.vstack([np.eye(4)[:3], [0, 0, 1, 1]])), ValueError, "last row of the pose"),
    ]
    later = [
        ("track: another size", dict(rgb=rgb[:240], depth=depth[:240], mask=mask[:240]), ValueError, "rgb: image is 640x240 but the first frame's is 640x480"),
        ("track: no mask with given masks", dict(rgb=rgb, depth=depth, mask=None), ValueError, "every frame needs the object's mask"),
        ("track: depth bool", dict(rgb=rgb, depth=depth > 0, mask=mask), TypeError, "depth: expected dtype uint16"),
    ]
    return init, later, good


INIT_CASES, TRACK_CASES, GOOD = bad_argument_cases()


@pytest.mark.parametrize("case", INIT_CASES, ids=[c[0] for c in INIT_CASES])
def test_bad_initialize_arguments_raise(case):
    _, arguments, error, message = case
    with pytest.raises(error, match=message):
        bt.Tracker().initialize(**arguments)


@pytest.mark.parametrize("case", TRACK_CASES, ids=[c[0] for c in TRACK_CASES])
def test_bad_track_arguments_raise(case):
    _, arguments, error, message = case
    tracker = bt.Tracker()
    tracker.initialize(**GOOD)
    with pytest.raises(error, match=message):
        tracker.track(**arguments)


def test_track_before_initialize_and_a_mask_with_propagated_masks_raise():
    with pytest.raises(RuntimeError, match=r"track\(\) called before initialize\(\)"):
        bt.Tracker().track(GOOD["rgb"], GOOD["depth"], GOOD["mask"])
    tracker = bt.Tracker({"masks": {"source": "propagated"}})
    tracker.initialize(**GOOD)
    with pytest.raises(ValueError, match="masks.source is 'propagated'"):
        tracker.track(GOOD["rgb"], GOOD["depth"], GOOD["mask"])


def test_non_contiguous_and_nan_inputs_are_used_as_their_contiguous_copies(box):
    seq = box / "seq"
    sequence = bt.Sequence(str(seq))
    rgb, depth, mask = sequence.read(0)
    reference = bt.Tracker().initialize(rgb, depth, mask, sequence.K).mask
    strided = np.ascontiguousarray(rgb[:, ::-1])[:, ::-1]  # a view with negative strides
    holes = depth.copy()
    holes[depth == 0] = np.nan  # NaN: no reading, as 0
    result = bt.Tracker().initialize(strided, holes, mask.astype(bool), sequence.K)
    assert np.array_equal(result.mask, reference)


def test_metrics_bad_arguments():
    with pytest.raises(ValueError, match="1 poses for 2 true ones"):
        bt.score(np.zeros((3, 3)), [np.eye(4), np.eye(4)], [np.eye(4)])
    with pytest.raises(ValueError, match="model: expected an Nx3 array"):
        bt.score(np.zeros((3, 2)), [np.eye(4)], [np.eye(4)])
    with pytest.raises(ValueError, match=r"estimates\[0\]: rotation block"):
        bt.score(np.zeros((3, 3)), [np.eye(4)], [np.diag([1.0, 1, -1, 1])])
    with pytest.raises(ValueError, match="sequence directory not found"):
        bt.Sequence("/nonexistent/sequence")


@pytest.fixture(scope="session")
def two(tmp_path_factory):
    """Two synthetic objects (a box and a can passing in front of each other), in mask folders
    and in label images, and the CLI's poses of each."""
    root = tmp_path_factory.mktemp("two")
    run("bundletrack_synth", "--out", root / "seq", "--frames", FRAMES, "--objects", 2)
    run("bundletrack_synth", "--out", root / "labels", "--frames", FRAMES, "--objects", 2, "--labels")
    run("bundletrack_track", "--sequence", root / "seq", "--out", root / "cli", "--quiet")
    return root


def track_objects(seq):
    """Each object of a sequence of several through MultiTracker, from files read by OpenCV, each
    starting at its annotated pose, as bundletrack_track does."""
    sequence = bt.Sequence(str(seq))
    tracker = bt.MultiTracker(sequence.objects, sequence.K)
    poses = {name: [] for name in sequence.objects}
    for i in range(len(sequence)):
        rgb, depth, _ = files(seq, i)
        masks = {name: cv2.imread(str(seq / "masks" / name / f"{i:06d}.png"), cv2.IMREAD_UNCHANGED)
                 for name in sequence.objects}
        starts = {name: sequence.ground_truth(i, name) for name in sequence.objects}
        for name, result in tracker.track(rgb, depth, masks, starts).items():
            assert result is not None  # both objects are in view from the first frame
            poses[name].append(result.pose)
    assert tracker.started == {name: True for name in sequence.objects}
    return poses


def test_multi_tracker_gives_the_cli_poses_of_each_object(two):
    poses = track_objects(two / "seq")
    assert sorted(poses) == ["box", "cylinder"]
    for name, estimates in poses.items():
        assert largest_difference(estimates, cli_poses(two / "cli", name)) <= 1e-9
        truth = [np.loadtxt(two / "seq" / "annotated_poses" / name / f"{i:06d}.txt") for i in range(FRAMES)]
        model = np.loadtxt(two / "seq" / "model" / name / "points.xyz")
        assert bt.score(model, truth, estimates)["adds_auc"] > 95


def test_sequence_masks_of_folders_and_label_images_are_the_files(two, box):
    folders, labels = bt.Sequence(str(two / "seq")), bt.Sequence(str(two / "labels"))
    assert folders.objects == labels.objects == ["box", "cylinder"]
    for i in (0, FRAMES - 1):
        label_image = cv2.imread(str(two / "labels" / "labels" / f"{i:06d}.png"), cv2.IMREAD_UNCHANGED)
        for label, name in enumerate(folders.objects, start=1):
            mask = cv2.imread(str(two / "seq" / "masks" / name / f"{i:06d}.png"), cv2.IMREAD_UNCHANGED)
            assert np.array_equal(folders.masks(i)[name], mask)
            assert np.array_equal(labels.masks(i)[name], np.where(label_image == label, 255, 0).astype(np.uint8))
            assert np.array_equal(labels.masks(i)[name], mask)
    assert folders.model_points("cylinder").shape[1] == 3
    assert bt.Sequence(str(box / "seq")).objects == []
    with pytest.raises(ValueError, match="a sequence of one object"):
        bt.Sequence(str(box / "seq")).masks(0)


def test_multi_tracker_bad_arguments_raise(two):
    seq = two / "seq"
    sequence = bt.Sequence(str(seq))
    rgb, depth, _ = files(seq, 0)
    masks = sequence.masks(0)
    with pytest.raises(ValueError, match="objects: name at least one object"):
        bt.MultiTracker([], sequence.K)
    with pytest.raises(ValueError, match="objects: 'box' is named twice"):
        bt.MultiTracker(["box", "box"], sequence.K)
    with pytest.raises(ValueError, match="K: expected a 3x3 matrix"):
        bt.MultiTracker(["box"], np.eye(2))
    tracker = bt.MultiTracker(sequence.objects, sequence.K)
    with pytest.raises(TypeError, match="masks: expected a dict from object names"):
        tracker.track(rgb, depth, [masks["box"]])
    with pytest.raises(ValueError, match=r"masks: no object 'plate' \(objects: box, cylinder\)"):
        tracker.track(rgb, depth, {"plate": masks["box"]})
    with pytest.raises(ValueError, match=r"poses\['box'\]: rotation block is not a rotation"):
        tracker.track(rgb, depth, masks, {"box": np.diag([2.0, 1, 1, 1])})
    with pytest.raises(ValueError, match=r"mask"):
        tracker.track(rgb, depth, {"box": masks["box"][:10]})
    results = tracker.track(rgb, depth, {"box": masks["box"]})  # the can sits the first frame out
    assert results["box"].tracked and results["cylinder"] is None
    assert tracker.started == {"box": True, "cylinder": False}
    with pytest.raises(ValueError, match="rgb: image is 640x240"):
        tracker.track(rgb[:240], depth[:240], {})
    propagated = bt.MultiTracker(sequence.objects, sequence.K, {"masks": {"source": "propagated"}})
    propagated.track(rgb, depth, masks)
    with pytest.raises(ValueError, match=r"masks\['box'\]: masks.source is 'propagated'"):
        propagated.track(rgb, depth, masks)
    with pytest.raises(ValueError, match="no object 'plate'"):
        tracker.object_model("plate")
    assert tracker.object_model("box")["points"].shape[1] == 3


def test_depth_beyond_the_sensors_range_warns_naming_the_unit(box):
    # 0.2 mm units read as millimetres: a wall at 1.2 m and the object at 1 m seem 6 m and 5 m away.
    sequence = bt.Sequence(str(box / "seq"))
    rgb, _, mask = files(box / "seq", 0)
    depth = np.full(mask.shape, 6000, np.uint16)
    depth[mask > 0] = 5000
    with pytest.warns(UserWarning, match=r"more than the 4.00 m that the sensor .* 0\.0002"):
        bt.Tracker().initialize(rgb, depth, mask, sequence.K)
    with pytest.warns(UserWarning, match=r"more than the 4.00 m"):
        bt.MultiTracker(["box"], sequence.K).track(rgb, depth, {"box": mask})
