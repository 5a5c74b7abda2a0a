"""`read_bvh` reads motion capture as `imitate retarget` does."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import imitate
from conftest import shared


@pytest.mark.parametrize(
    "parts", [("mocap", "real", "boxing.bvh"), ("mocap", "bandai", "dataset-1_bow_active_001.bvh")]
)
def test_a_shared_take_reads_as_the_cli_retargets_it_joint_for_joint(tmp_path, cli, parts):
    source = shared(*parts)
    cli("retarget", source, "-o", tmp_path / "cli.bvh")
    with warnings.catch_warnings(record=True) as warned:
        warnings.simplefilter("always")
        motion = imitate.read_bvh(source)
    # The reader's and the retargeting's warnings, each naming the file.
    assert all(f"{source}: warning: " in str(w.message) for w in warned)
    motion.write_bvh(tmp_path / "py.bvh")
    # The same canonical BVH, byte for byte.
    assert (tmp_path / "py.bvh").read_bytes() == (tmp_path / "cli.bvh").read_bytes()
    # And the CLI's file read back holds the same joints, within its text's
    # rounding.
    written = imitate.read_bvh(tmp_path / "cli.bvh")
    positions = motion.positions()
    assert positions.shape == (len(motion), 17, 3)
    assert np.abs(written.positions() - positions).max() < 1e-4
    assert motion.joint_names == imitate.JOINT_NAMES
    assert motion.joint_space().shape == (len(motion), 43)
    assert motion.root().shape == (len(motion), 4)
    assert motion.fps == pytest.approx(1.0 / motion.frame_time_s)
    # The root column is the pelvis.
    assert np.allclose(motion.root()[:, :3], positions[:, 0, :])


def test_a_canonical_take_stands_on_the_ground_and_moves_its_arms():
    motion = imitate.read_bvh("mocap/wave-h.bvh")
    positions = motion.positions()
    head, ankle = imitate.JOINT_NAMES.index("head"), imitate.JOINT_NAMES.index("left_ankle")
    assert 1.3 < positions[:, head, 1].mean() < 1.9
    assert positions[:, ankle, 1].min() < 0.2
    wrist = imitate.JOINT_NAMES.index("right_wrist")
    assert np.ptp(positions[:, wrist, 0]) > 0.2


def test_a_missing_file_raises_a_bvh_error_naming_it(tmp_path, cli):
    missing = tmp_path / "none.bvh"
    with pytest.raises(imitate.BvhError) as caught:
        imitate.read_bvh(missing)
    assert caught.value.path == str(missing)
    assert str(missing) in str(caught.value)
    assert isinstance(caught.value, imitate.Error)


def test_a_malformed_file_raises_the_message_the_cli_prints(tmp_path, cli):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 zero\n")
    with pytest.raises(imitate.BvhError) as caught:
        imitate.read_bvh(bad)
    printed = cli("retarget", bad, "-o", tmp_path / "out.bvh", check=False)
    assert printed.returncode == 1
    assert printed.stderr.strip() == f"imitate: error: {caught.value}"
    assert caught.value.path == str(bad)
    assert ":4:" in str(caught.value)


def test_an_unknown_up_axis_is_an_options_error():
    with pytest.raises(imitate.OptionsError, match="up: `x`"):
        imitate.read_bvh("mocap/wave-h.bvh", up="x")
    with pytest.raises(ValueError):
        imitate.read_bvh("mocap/wave-h.bvh", up="x")
