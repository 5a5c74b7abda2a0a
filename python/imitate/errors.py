"""The exceptions imitate raises: one hierarchy under :class:`Error`.

Every message is the one the ``imitate`` command prints for the same
problem, and names the file (and line, for text formats) at fault; ``path``
holds that file where there is one.
"""

from __future__ import annotations

from typing import Optional


class Error(Exception):
    """Something imitate could not do; ``path`` is the file at fault, or None."""

    def __init__(self, message: str, path: Optional[str] = None) -> None:
        super().__init__(message)
        self.path = path


class BvhError(Error):
    """A BVH file (or a mapping file, or a folder of takes) that cannot be
    read or put onto the canonical body."""


class VocabularyError(Error):
    """A vocabulary that cannot be read, written or learned: truncated,
    corrupt, of another format version, made for another body."""


class VideoError(Error):
    """Frames that cannot be read: a missing or corrupt image or video,
    frames of mixed sizes, no frame rate."""


class CameraError(Error):
    """A camera that cannot be read or used, or that cannot be estimated
    from the frames."""


class OptionsError(Error, ValueError):
    """An option out of range or at odds with another; the message names
    the keyword argument."""


__all__ = ["Error", "BvhError", "VocabularyError", "VideoError", "CameraError", "OptionsError"]
