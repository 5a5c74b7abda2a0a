"""Tracking from Python: whole clips as `imitate track`, frame by frame with
`Tracker`, scores and the humanoid as the CLI's, and bad input refused."""

from __future__ import annotations

import json
import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import polars as pl
import pytest

import imitate
from conftest import read_csv, shared


def test_track_returns_exactly_the_cli_frames_csv(tmp_path, clip, run_dir):
    expected = read_csv(run_dir / "frames.csv")
    frames = imitate.track(clip / "frames", "vocab/default.vocab")
    pd.testing.assert_frame_equal(frames, expected)
    assert list(frames.columns) == list(expected.columns)
    # On one thread of its own, as a batch task runs it: the same table.
    pd.testing.assert_frame_equal(imitate.track(clip / "frames", "vocab/default.vocab", threads=1), expected)
    with pytest.raises(imitate.OptionsError, match="threads: must be at least 1"):
        imitate.track(clip / "frames", "vocab/default.vocab", threads=0)
    # polars, and the run folder written as the CLI writes it.
    vocab = imitate.Vocabulary.load("vocab/default.vocab")
    table = imitate.track(clip / "frames", vocab, out=tmp_path / "run", frame="polars")
    assert isinstance(table, pl.DataFrame)
    assert table.columns == list(expected.columns) and table.height == len(expected)
    for name in ["frames.csv", "likelihoods.csv", "trajectory.bvh", "camera.json"]:
        assert (tmp_path / "run" / name).read_bytes() == (run_dir / name).read_bytes(), name
    with pytest.raises(imitate.Error, match="exists and is not empty") as caught:
        imitate.track(clip / "frames", vocab, out=tmp_path / "run")
    assert caught.value.path == str(tmp_path / "run")


def test_tracker_step_frame_by_frame_equals_track(clip, run_dir):
    expected = read_csv(run_dir / "frames.csv")
    summary = json.loads((run_dir / "summary.json").read_text())
    camera = imitate.Camera.from_json(clip / "camera.json")
    # `imitate track`'s defaults: eq. 7 (no feedback), seed 0.
    tracker = imitate.Tracker("vocab/default.vocab", camera, feedback=False, seed=0, fps=summary["fps"])
    masks = imitate.silhouettes(clip / "frames")
    assert masks.size == (camera.width, camera.height)
    names = tracker.names
    count = 0
    for row, mask in zip(expected.to_dict("records"), masks):
        estimate = tracker.step(silhouette=mask)
        assert estimate.frame == row["frame"] and estimate.time_s == row["time_s"]
        activity = row["activity"] if isinstance(row["activity"], str) else None
        assert estimate.activity == activity
        for name in names:
            assert estimate.probabilities[name] == row[f"prob_{name}"]
            assert estimate.progress[name] == row[f"progress_{name}"]
        assert estimate.root == (row["root_x"], row["root_y"], row["root_z"], row["root_heading"])
        joints = [[row[f"{j}_{axis}"] for axis in "xyz"] for j in imitate.JOINT_NAMES]
        assert np.array_equal(estimate.joints, np.array(joints))
        assert estimate.unexplained == bool(row["unexplained"])
        count += 1
    assert count == len(expected) == tracker.frames


def test_a_tracker_without_a_camera_frames_the_front_preset_and_coasts_without_input():
    tracker = imitate.Tracker("vocab/default.vocab")
    mask = np.zeros((120, 160), dtype=np.uint8)
    mask[30:100, 70:90] = 255
    estimate = tracker.step(silhouette=mask)
    assert tracker.camera.spec == imitate.Camera.preset("front", 160, 120).spec
    assert set(estimate.probabilities) == set(tracker.names)
    assert math.isclose(sum(estimate.probabilities.values()), 1.0)
    assert estimate.joints.shape == (17, 3)
    coasting = tracker.step()
    assert coasting.activity is None and coasting.probabilities is None and coasting.unexplained is None


def test_keypoints_alone_are_tracked_and_nan_is_refused(clip):
    camera = imitate.Camera.from_json(clip / "camera.json")
    motion = imitate.read_bvh("mocap/wave-h.bvh")
    tracker = imitate.Tracker("vocab/default.vocab", camera)
    # The sites a detector would see, drawn from the take's own joints.
    site_joint = {
        "neck": "neck", "left_shoulder": "left_shoulder", "right_shoulder": "right_shoulder",
        "left_elbow": "left_elbow", "right_elbow": "right_elbow", "left_wrist": "left_wrist",
        "right_wrist": "right_wrist", "left_hip": "left_hip", "right_hip": "right_hip",
        "left_knee": "left_knee", "right_knee": "right_knee", "left_ankle": "left_ankle",
        "right_ankle": "right_ankle",
    }
    points = np.zeros((len(imitate.KEYPOINT_SITES), 3))
    projected = camera.project(motion.positions()[0])
    for i, site in enumerate(imitate.KEYPOINT_SITES):
        if site in site_joint:
            u, v, _ = projected[imitate.JOINT_NAMES.index(site_joint[site])]
            points[i] = (u, v, 1.0)
    estimate = tracker.step(keypoints=points)
    assert estimate.activity in tracker.names
    assert estimate.fit["keypoints"] is not None and estimate.fit["silhouette"] is None
    points[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"keypoints: row 3 .*finite"):
        tracker.step(keypoints=points)
    with pytest.raises(ValueError, match=r"\(15, 3\)"):
        tracker.step(keypoints=points[:, :2])


def test_masks_of_another_shape_or_type_are_refused(clip):
    tracker = imitate.Tracker("vocab/default.vocab", imitate.Camera.from_json(clip / "camera.json"))
    with pytest.raises(ValueError, match=r"expected an array of shape \(120, 160\).*not \(160, 120\)"):
        tracker.step(silhouette=np.zeros((160, 120), dtype=bool))
    with pytest.raises(ValueError, match=r"\(120, 160\).*not \(120, 160, 3\)"):
        tracker.step(silhouette=np.zeros((120, 160, 3), dtype=np.uint8))
    with pytest.raises(TypeError, match="bool or uint8"):
        tracker.step(silhouette=np.zeros((120, 160), dtype=np.float32))
    with pytest.raises(TypeError, match="NumPy array"):
        tracker.step(silhouette=[[0] * 160] * 120)
    assert tracker.frames == 0


def test_score_is_the_cli_metrics(tmp_path, cli, clip, run_dir):
    metrics = imitate.score(run_dir, clip / "truth.csv")
    cli("score", run_dir, "--truth", clip / "truth.csv", "-o", tmp_path / "metrics.json")
    assert metrics == json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["upper_body_mm"] < 100


def test_execute_returns_the_cli_execution_table_and_writes_its_folder(tmp_path, cli):
    cli("execute", "mocap/punch.bvh", "-o", tmp_path / "run", "--fixed-base")
    table = imitate.execute("mocap/punch.bvh", out=tmp_path / "mine", fixed_base=True)
    pd.testing.assert_frame_equal(table, read_csv(tmp_path / "run" / "execution.csv"))
    for name in ["executed.bvh", "execution.csv", "summary.json"]:
        assert (tmp_path / "mine" / name).read_bytes() == (tmp_path / "run" / name).read_bytes(), name
    # The command's default rate is the package's.
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["rate_hz"] == imitate.EXECUTE_RATE_HZ
    with pytest.raises(imitate.Error, match="exists and is not empty"):
        imitate.execute("mocap/punch.bvh", out=tmp_path / "mine", fixed_base=True)


def test_execute_plans_swings_as_the_cli_does_and_refuses_an_impossible_lookahead(tmp_path, cli):
    cli("execute", "mocap/punch.bvh", "-o", tmp_path / "run", "--lookahead", "0.5")
    imitate.execute("mocap/punch.bvh", out=tmp_path / "mine", lookahead=0.5)
    summary = json.loads((tmp_path / "mine" / "summary.json").read_text())
    assert summary == json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["lookahead_s"] == 0.5
    for bad in [-1.0, 6.0, float("nan")]:
        with pytest.raises(imitate.OptionsError, match="^lookahead: how far ahead each swing is planned"):
            imitate.execute("mocap/punch.bvh", lookahead=bad)


def test_execute_by_the_primitives_matches_the_cli(tmp_path, cli, run_dir):
    cli("execute", "--primitives", run_dir, "-o", tmp_path / "run", "--fixed-base")
    table = imitate.execute(primitives=run_dir, out=tmp_path / "mine", fixed_base=True)
    pd.testing.assert_frame_equal(table, read_csv(tmp_path / "run" / "execution.csv"))
    assert (tmp_path / "mine" / "summary.json").read_bytes() == (tmp_path / "run" / "summary.json").read_bytes()
    with pytest.raises(imitate.OptionsError, match="one of them"):
        imitate.execute("mocap/punch.bvh", primitives=run_dir)
    with pytest.raises(imitate.OptionsError, match="truth: scores an imitation by the primitives only"):
        imitate.execute("mocap/punch.bvh", truth="video/truth.csv")


def test_execute_with_assistance_matches_the_cli_and_refuses_a_fixed_base(tmp_path, cli):
    cli("execute", "mocap/punch.bvh", "-o", tmp_path / "run", "--assist")
    table = imitate.execute("mocap/punch.bvh", assist=True)
    pd.testing.assert_frame_equal(table, read_csv(tmp_path / "run" / "execution.csv"))
    # Standing, the punch's capture point never leaves its feet: nothing
    # pushes, and the torque turns the pelvis.
    assert (table["assist_torque_nm"] > 0).any() and (table["assist_force_n"] == 0).all()
    with pytest.raises(imitate.OptionsError, match="assist: assistance holds a humanoid up on the ground"):
        imitate.execute("mocap/punch.bvh", assist=True, fixed_base=True)


def test_bad_inputs_name_the_file(tmp_path, cli, clip):
    with pytest.raises(imitate.VideoError) as caught:
        imitate.track(tmp_path / "none", "vocab/default.vocab")
    assert caught.value.path == str(tmp_path / "none")
    printed = cli("track", tmp_path / "none", "--vocab", "vocab/default.vocab", "-o", tmp_path / "run", check=False)
    assert printed.stderr.strip() == f"imitate: error: {caught.value}"
    with pytest.raises(imitate.VocabularyError) as caught:
        imitate.track(clip / "frames", tmp_path / "none.vocab")
    assert caught.value.path == str(tmp_path / "none.vocab")
    with pytest.raises(imitate.CameraError) as caught:
        imitate.Camera.from_json(tmp_path / "none.json")
    assert caught.value.path == str(tmp_path / "none.json")
    with pytest.raises(imitate.OptionsError, match="^particles: "):
        imitate.track(clip / "frames", "vocab/default.vocab", particles=0)
    with pytest.raises(imitate.OptionsError, match="^work_size: "):
        imitate.track(clip / "frames", "vocab/default.vocab", work_size=8)
    with pytest.raises(TypeError, match="partcles"):
        imitate.track(clip / "frames", "vocab/default.vocab", partcles=3)
    with pytest.raises(imitate.OptionsError, match="^particles: "):
        imitate.Tracker("vocab/default.vocab", particles=0)


def test_a_camera_projects_as_camera_json_says():
    camera = imitate.Camera(160, 120, 200.0, 200.0, 80.0, 60.0, (0.0, 1.0, 4.0), (0.0, 1.0, 0.0))
    assert camera.project([0.0, 1.0, 0.0]).tolist() == [80.0, 60.0, 4.0]
    uv = camera.project(np.array([[0.5, 1.0, 0.0], [0.0, 1.0, 8.0]]))
    # Image right is the world's +x for a camera looking down -z.
    assert uv[0].tolist() == pytest.approx([80.0 + 25.0, 60.0, 4.0])
    assert np.isnan(uv[1]).all()
    with pytest.raises(imitate.CameraError, match="look_at"):
        imitate.Camera(160, 120, 200.0, 200.0, 80.0, 60.0, (0.0, 1.0, 4.0), (0.0, 1.0, 4.0))


def test_trackers_in_threads_give_what_each_gives_alone(clip):
    # Each step releases the GIL; two trackers stepping at once must not
    # disturb each other.
    camera = imitate.Camera.from_json(clip / "camera.json")
    masks = list(imitate.silhouettes(clip / "frames"))[:30]

    def follow(seed):
        tracker = imitate.Tracker("vocab/default.vocab", camera, seed=seed)
        return np.stack([tracker.step(silhouette=m).joints for m in masks])

    alone = [follow(seed) for seed in (1, 2)]
    with ThreadPoolExecutor(2) as pool:
        together = list(pool.map(follow, (1, 2)))
    assert all(np.array_equal(a, b) for a, b in zip(alone, together))
    # A tracker on a pool of one thread of its own follows the same way.
    tracker = imitate.Tracker("vocab/default.vocab", camera, seed=1, threads=1)
    assert np.array_equal(np.stack([tracker.step(silhouette=m).joints for m in masks]), alone[0])


def test_execute_warns_of_a_left_out_bind_pose_and_of_a_start_in_the_air(tmp_path):
    with pytest.warns(UserWarning, match=r"boxing\.bvh: the first frame is left out as a bind pose .*skip=0 keeps it"):
        imitate.execute(shared("mocap", "real", "boxing.bvh"), fixed_base=True)
    # The punch with its root raised half a metre on every frame.
    lines = Path("mocap/punch.bvh").read_text().splitlines()
    start = lines.index("MOTION") + 3
    for k in range(start, len(lines)):
        values = lines[k].split()
        values[1] = f"{float(values[1]) + 0.5:.6f}"
        lines[k] = " ".join(values)
    raised = tmp_path / "raised.bvh"
    raised.write_text("\n".join(lines) + "\n")
    with pytest.warns(UserWarning, match=r"raised\.bvh: warning: the first frame's lowest point lies 0\.50 m above"):
        imitate.execute(raised)
