"""Shared fixtures: the repository, the `imitate` binary the Python results
are checked against, the shared motion capture, and one rendered clip."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("IMITATE_SHARED", REPO.parent / "shared"))


def _binary() -> Path:
    if "IMITATE_BIN" in os.environ:
        return Path(os.environ["IMITATE_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", Path.home() / ".cache/imitate/target"))
    return target / "release" / "imitate"


@pytest.fixture(scope="session")
def imitate_bin() -> Path:
    """The release binary (IMITATE_BIN overrides where it is looked for)."""
    binary = _binary()
    if not binary.is_file():
        pytest.fail(f"{binary}: no imitate binary; build it with `cargo build --release` or set IMITATE_BIN")
    return binary


@pytest.fixture(scope="session")
def cli(imitate_bin):
    """Runs `imitate ARGS…` in the repository's root (vocabularies record
    their sources as given, so both front-ends must see the same paths)."""

    def run(*args, check: bool = True) -> subprocess.CompletedProcess:
        done = subprocess.run(
            [str(imitate_bin), "-q", *map(str, args)], cwd=REPO, capture_output=True, text=True
        )
        if check and done.returncode != 0:
            raise AssertionError(f"imitate {' '.join(map(str, args))} failed: {done.stderr}")
        return done

    return run


@pytest.fixture(autouse=True)
def in_repo(monkeypatch):
    """Every test runs in the repository's root, as the CLI above does."""
    monkeypatch.chdir(REPO)


def read_csv(path: Path):
    """A CSV file as pandas reads it exactly (as `imitate.track` does)."""
    import pandas

    exact = {} if int(pandas.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    return pandas.read_csv(path, **exact)


def shared(*parts: str) -> Path:
    """A path under the shared data beside the repository; its absence is a
    skip, but a failure under CI (CI set)."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        message = f"{path}: the shared data is missing"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def clip(tmp_path_factory, cli) -> Path:
    """`mocap/wave-h.bvh` rendered at 160×120, 15 frames a second, labelled:
    DIR/frames/*.png, DIR/camera.json, DIR/truth.csv."""
    out = tmp_path_factory.mktemp("clip") / "wave-h"
    cli("render", "mocap/wave-h.bvh", "-o", out, "--labels", "mocap/labels.csv")
    return out


@pytest.fixture(scope="session")
def run_dir(tmp_path_factory, cli, clip) -> Path:
    """`imitate track` of the clip with the shipped vocabulary."""
    out = tmp_path_factory.mktemp("run") / "run"
    cli("track", clip / "frames", "--vocab", "vocab/default.vocab", "-o", out)
    return out
