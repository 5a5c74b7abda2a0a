"""imitate: learn dynamical motion primitives from motion capture and follow
a person through one camera.

The Python face of the ``imitate`` Rust library: the same code the
``imitate`` command runs, with NumPy arrays and pandas or polars tables in
and out. A tour::

    import imitate

    motion = imitate.read_bvh("take.bvh")            # any BVH, canonical body
    motion.positions()                               # frames × 17 × 3, meters
    vocab = imitate.Vocabulary.build(["mocap/"], labels="mocap/labels.csv")
    vocab.save("mine.vocab")
    frames = imitate.track("clip.mp4", vocab)        # frames.csv as a DataFrame
    tracker = imitate.Tracker(vocab, imitate.Camera.from_json("camera.json"))
    estimate = tracker.step(silhouette=mask)         # one frame at a time

See docs/python.md for every function and class.
"""

from __future__ import annotations

import io
import json
import os
from typing import TYPE_CHECKING, Any, Dict, Optional, Tuple, Union

from . import _imitate
from ._imitate import (
    EXECUTE_LOOKAHEAD_S,
    EXECUTE_RATE_HZ,
    JOINT_NAMES,
    KEYPOINT_SITES,
    Camera,
    FrameEstimate,
    Motion,
    Primitive,
    Silhouettes,
    Tracker,
    Vocabulary,
    __version__,
    read_bvh,
    segment,
)
from .errors import BvhError, CameraError, Error, OptionsError, VideoError, VocabularyError

if TYPE_CHECKING:
    PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "EXECUTE_LOOKAHEAD_S",
    "EXECUTE_RATE_HZ",
    "JOINT_NAMES",
    "KEYPOINT_SITES",
    "BvhError",
    "Camera",
    "CameraError",
    "Error",
    "FrameEstimate",
    "Motion",
    "OptionsError",
    "Primitive",
    "Silhouettes",
    "Tracker",
    "VideoError",
    "Vocabulary",
    "VocabularyError",
    "__version__",
    "execute",
    "read_bvh",
    "score",
    "segment",
    "silhouettes",
    "track",
]

_FRAMES = ("pandas", "polars")


def _table(text: str, frame: str) -> Any:
    """A CSV table the library wrote, as a DataFrame of the kind asked for."""
    if frame == "polars":
        import polars

        # Every row is read before a column's type is chosen: a column empty
        # on the first frames (a coasting tracker's activity) holds text later.
        return polars.read_csv(io.StringIO(text), infer_schema_length=None)
    import pandas

    # Numbers parsed back exactly as the library wrote them: pandas 3 does
    # by default, earlier versions when asked.
    exact = {} if int(pandas.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    return pandas.read_csv(io.StringIO(text), **exact)


def _check_frame(frame: str) -> None:
    if frame not in _FRAMES:
        raise OptionsError(f'frame: `{frame}` is not "pandas" or "polars"')


def silhouettes(input: PathLike, background: Optional[PathLike] = None, work_size: int = 320) -> Silhouettes:
    """The silhouettes of a clip (a folder of PNG or JPEG images, or a video
    read through ffmpeg) frame by frame, as ``imitate track`` makes them:
    H × W bool arrays at the working width ``work_size`` (0: the frames' own
    size). ``background`` is the empty scene for color frames; without it,
    a background.png beside the frames or one learned from them."""
    return Silhouettes(input, background, work_size)


def track(
    input: PathLike,
    vocab: Union[Vocabulary, PathLike],
    out: Optional[PathLike] = None,
    frame: str = "pandas",
    force: bool = False,
    threads: Optional[int] = None,
    **options: Any,
) -> Any:
    """Tracks a clip as ``imitate track`` does and returns its frames.csv as
    a DataFrame (``frame="pandas"`` or ``"polars"``), with exactly that
    file's columns.

    ``input`` is a folder of images (silhouettes or color) or a video;
    ``vocab`` a :class:`Vocabulary` or a ``.vocab`` path. With ``out``, the
    run folder (trajectory.bvh, frames.csv, likelihoods.csv, camera.json,
    summary.json) is written there too; a folder that holds something is
    refused unless ``force``.

    The options are ``imitate track``'s flags in snake case with the same
    defaults: ``camera`` (a :class:`Camera`, a camera.json path, a preset
    name or ``"auto"``; default: the camera.json beside the frames, else
    ``"auto"``), ``fov``, ``focal``, ``particles=6``, ``lookahead=5``,
    ``seed=0``, ``feedback=False``, ``fps``, ``height``, ``calibrate=True``,
    ``background``, ``work_size=320``, ``baseline`` (``"full_space"``),
    ``keypoints``, ``observe`` (``"silhouette"``, ``"keypoints"``,
    ``"both"``), ``unexplained_below=0.5``. The GIL is released while it
    tracks, on ``threads`` threads of its own (default: every core; give
    the share of cores the call has when several run side by side). The
    result is the same whatever ``threads`` is.
    """
    _check_frame(frame)
    text = _imitate.track_frames(input, vocab, out, force, threads, **options)
    return _table(text, frame)


def score(run: PathLike, truth: PathLike, settle: float = 0.5) -> Dict[str, Any]:
    """Scores a run folder against the truth.csv ``imitate render`` wrote
    with its video, as ``imitate score --truth``: the metrics.json object
    (joint errors in mm, limb errors in degrees, recognition).
    ``settle`` is the seconds after each switch of activity that the
    settled accuracy leaves out."""
    return json.loads(_imitate.score_run(run, truth, settle))


def execute(
    motion: Union[Motion, PathLike, None] = None,
    out: Optional[PathLike] = None,
    force: bool = False,
    frame: str = "pandas",
    fixed_base: bool = False,
    balance: bool = True,
    gains: Tuple[float, float] = (10000.0, 200.0),
    rate: float = EXECUTE_RATE_HZ,
    skip: Optional[int] = None,
    assist: bool = False,
    primitives: Optional[PathLike] = None,
    truth: Optional[PathLike] = None,
    up: Optional[str] = None,
    mapping: Optional[PathLike] = None,
    lookahead: float = EXECUTE_LOOKAHEAD_S,
) -> Any:
    """Plays a motion (a :class:`Motion`, or a BVH path read with ``up`` and
    ``mapping``) on the simulated humanoid as ``imitate execute`` does and
    returns its execution.csv as a DataFrame: per frame, the root, and per
    joint the target and reached angles, torques and errors.

    ``fixed_base`` holds the pelvis in place; ``balance=False`` leaves the
    ankles to the trajectory; ``gains`` are the motors' stiffness and
    damping (KP 1/s², KD 1/s); ``rate`` the physics steps a second;
    ``skip`` leaves out the first frames (by default the first one when it
    is a bind pose, as ``imitate execute`` does, with a ``UserWarning``;
    ``skip=0`` keeps it; a first frame off the floor is warned of too);
    ``assist`` holds the humanoid up with a residual force (keeping the
    capture point over the feet) and torque (turning the pelvis toward the
    trajectory's) on the pelvis, reported in the table
    (``assist_force_n``, ``assist_torque_nm``); ``lookahead`` is how far
    ahead, in seconds, each swing's foot placements are played to choose
    where the foot lands (0: where the capture point says, unplanned,
    faster; never with ``assist``). With ``primitives`` (a ``track`` run folder, in
    place of ``motion``) the run's trajectory is imitated by its
    vocabulary's primitives, as ``imitate execute --primitives`` does,
    scored against ``truth`` (a truth.csv) when given. With
    ``out``, the execution's folder (executed.bvh, execution.csv,
    summary.json) is written there too; a folder that holds something is
    refused unless ``force``."""
    _check_frame(frame)
    if (motion is None) == (primitives is None):
        raise OptionsError("execute: give a motion or primitives=RUN_DIR, one of them")
    if primitives is not None:
        motion = read_bvh(os.path.join(os.fspath(primitives), "trajectory.bvh"), up, mapping)
    elif not isinstance(motion, Motion):
        motion = read_bvh(motion, up, mapping)
    text = _imitate.execute_table(
        motion, out, force, fixed_base, balance, tuple(gains), rate, skip, assist, primitives, truth, lookahead
    )
    return _table(text, frame)

