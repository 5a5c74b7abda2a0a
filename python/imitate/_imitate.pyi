"""Types of imitate's Rust extension; the package re-exports them."""

import os
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Floats = npt.ArrayLike

JOINT_NAMES: List[str]
"""The 17 canonical joints, in the order of every joints array."""
KEYPOINT_SITES: List[str]
"""The 15 keypoint sites, in the order of a keypoints array's rows."""
EXECUTE_RATE_HZ: float
EXECUTE_LOOKAHEAD_S: float
"""The physics rate ``execute`` runs at by default, steps a second."""
__version__: str

def read_bvh(path: _Path, up: Optional[str] = None, mapping: Optional[_Path] = None) -> Motion:
    """Reads a BVH file onto the canonical humanoid, as ``imitate retarget``."""

class Motion:
    """A take of the canonical body."""

    @property
    def fps(self) -> float: ...
    @property
    def frame_time_s(self) -> float: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def source(self) -> str: ...
    def __len__(self) -> int: ...
    def positions(self) -> npt.NDArray[np.float64]:
        """World positions of every joint, meters: frames × 17 × 3."""
    def joint_space(self) -> npt.NDArray[np.float64]:
        """The joint space (the paper's x): frames × 43."""
    def root(self) -> npt.NDArray[np.float64]:
        """Pelvis x, y, z and heading: frames × 4."""
    def times(self) -> npt.NDArray[np.float64]:
        """Seconds from the first frame, per frame."""
    def write_bvh(self, path: _Path) -> None:
        """Writes canonical BVH, as ``imitate retarget``."""

class Vocabulary:
    """A vocabulary of motion primitives."""

    @staticmethod
    def load(path: _Path) -> Vocabulary: ...
    @staticmethod
    def build(paths: Union[_Path, Sequence[_Path]], labels: Optional[_Path] = None, **options: Any) -> Vocabulary:
        """Learns a vocabulary as ``imitate vocab build``; options are its flags in snake case."""
    def save(self, path: _Path) -> None: ...
    def info(self) -> Dict[str, Any]:
        """The object ``imitate vocab info --json`` prints."""
    @property
    def names(self) -> List[str]: ...
    @property
    def path(self) -> Optional[str]: ...
    def __len__(self) -> int: ...
    def __getitem__(self, key: Union[int, str]) -> Primitive: ...
    def __iter__(self) -> Iterator[Primitive]: ...

class Primitive:
    """One primitive: latent space (eq. 3), gradient field (eq. 2), progress."""

    @property
    def name(self) -> str: ...
    @property
    def dims(self) -> int: ...
    @property
    def label(self) -> Optional[str]: ...
    @property
    def mean(self) -> npt.NDArray[np.float64]: ...
    @property
    def basis(self) -> npt.NDArray[np.float64]: ...
    @property
    def variances(self) -> npt.NDArray[np.float64]: ...
    @property
    def variance_kept(self) -> float: ...
    @property
    def latent(self) -> npt.NDArray[np.float64]: ...
    @property
    def velocity(self) -> npt.NDArray[np.float64]: ...
    @property
    def phases(self) -> npt.NDArray[np.float64]: ...
    @property
    def speed(self) -> Dict[str, float]: ...
    @property
    def sources(self) -> List[Dict[str, Any]]: ...
    def field(self, y: _Floats) -> npt.NDArray[np.float64]: ...
    def progress(self, y: _Floats) -> Union[float, npt.NDArray[np.float64]]: ...
    def project(self, x: _Floats) -> npt.NDArray[np.float64]: ...
    def reconstruct(self, y: _Floats) -> npt.NDArray[np.float64]: ...

class Camera:
    """A pinhole camera, as camera.json holds it."""

    def __init__(
        self,
        width: int,
        height: int,
        fx: float,
        fy: float,
        cx: float,
        cy: float,
        position: Sequence[float],
        look_at: Sequence[float],
        up: Sequence[float] = (0.0, 1.0, 0.0),
    ) -> None: ...
    @staticmethod
    def from_json(path: _Path) -> Camera: ...
    @staticmethod
    def preset(name: str, width: int, height: int) -> Camera: ...
    def to_json(self) -> str: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def spec(self) -> Dict[str, Any]: ...
    def project(self, points: _Floats) -> npt.NDArray[np.float64]:
        """World points (3,) or (N, 3) to u, v (pixels) and depth; NaN behind."""

class FrameEstimate:
    """One frame's outcome, as a row of frames.csv."""

    @property
    def frame(self) -> int: ...
    @property
    def time_s(self) -> float: ...
    @property
    def activity(self) -> Optional[str]: ...
    @property
    def probabilities(self) -> Optional[Dict[str, float]]: ...
    @property
    def progress(self) -> Dict[str, float]: ...
    @property
    def joints(self) -> npt.NDArray[np.float64]: ...
    @property
    def root(self) -> Tuple[float, float, float, float]: ...
    @property
    def joint_space(self) -> npt.NDArray[np.float64]: ...
    @property
    def unexplained(self) -> Optional[bool]: ...
    @property
    def fit(self) -> Optional[Dict[str, Optional[float]]]: ...

class Tracker:
    """Follows one person frame by frame, as ``imitate track`` on each frame."""

    def __init__(
        self,
        vocab: Union[Vocabulary, _Path],
        camera: Optional[Union[Camera, _Path]] = None,
        *,
        particles: int = 6,
        lookahead: int = 5,
        feedback: bool = True,
        seed: int = 0,
        fps: float = 15.0,
        height: Optional[float] = None,
        calibrate: bool = True,
        unexplained_below: float = 0.5,
        threads: Optional[int] = None,
    ) -> None: ...
    def step(
        self, silhouette: Optional[npt.ArrayLike] = None, keypoints: Optional[npt.ArrayLike] = None
    ) -> FrameEstimate: ...
    @property
    def camera(self) -> Optional[Camera]: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def frames(self) -> int: ...

class Silhouettes:
    """A clip's silhouettes, frame by frame, as H × W bool arrays."""

    def __init__(self, input: _Path, background: Optional[_Path] = None, work_size: int = 320) -> None: ...
    @property
    def size(self) -> Tuple[int, int]: ...
    def __iter__(self) -> Iterator[npt.NDArray[np.bool_]]: ...
    def __next__(self) -> npt.NDArray[np.bool_]: ...

def segment(paths: Sequence[_Path], out: _Path, labels: Optional[_Path] = None, **options: Any) -> None:
    """Segments takes as ``imitate segment TAKES -o OUT`` and writes the table."""

def track_frames(
    input: _Path,
    vocab: Union[Vocabulary, _Path],
    out: Optional[_Path] = None,
    force: bool = False,
    threads: Optional[int] = None,
    **options: Any,
) -> str: ...
def score_run(run: _Path, truth: _Path, settle: float = 0.5) -> str: ...
def execute_table(
    motion: Motion,
    out: Optional[_Path] = None,
    force: bool = False,
    fixed_base: bool = False,
    balance: bool = True,
    gains: Tuple[float, float] = (10000.0, 200.0),
    rate: float = ...,
    skip: Optional[int] = None,
    assist: bool = False,
    primitives: Optional[_Path] = None,
    truth: Optional[_Path] = None,
    lookahead: float = ...,
) -> str: ...
