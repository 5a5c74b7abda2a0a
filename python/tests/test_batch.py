"""`python -m imitate.batch` on a local Ray cluster of 2 CPUs: one task per
clip or take, each result what running it alone gives, a failed task
reported with its clip while the others go on."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

if not os.environ.get("CI"):
    pytest.importorskip("ray")


def batch(*args) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.pop("RAY_ADDRESS", None)
    command = [sys.executable, "-m", "imitate.batch", *map(str, args), "--workers", "2"]
    return subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)


def test_batch_track_and_segment_give_what_each_alone_gives(tmp_path, cli, clip, run_dir):
    missing = tmp_path / "missing"
    done = batch("track", clip / "frames", missing, "--vocab", "vocab/default.vocab", "-o", tmp_path / "runs")
    assert done.returncode == 1, done.stderr
    # The clip folder `wave-h/frames` is named by its clip.
    for name in ["frames.csv", "likelihoods.csv", "trajectory.bvh", "camera.json"]:
        assert (tmp_path / "runs" / "wave-h" / name).read_bytes() == (run_dir / name).read_bytes(), name
    failed = [line for line in done.stderr.splitlines() if "error:" in line]
    assert len(failed) == 1 and f"missing: error: {missing}" in failed[0], done.stderr
    assert "1 of 2 done" in done.stderr

    takes = ["mocap/wave-h.bvh", "mocap/punch.bvh"]
    done = batch("segment", *takes, "-o", tmp_path / "segments", "--labels", "mocap/labels.csv")
    assert done.returncode == 0, done.stderr
    for take in takes:
        name = take.split("/")[1].replace(".bvh", ".csv")
        cli("segment", take, "-o", tmp_path / name, "--labels", "mocap/labels.csv")
        assert (tmp_path / "segments" / name).read_bytes() == (tmp_path / name).read_bytes(), take
