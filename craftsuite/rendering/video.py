"""MP4 rollout videos with OpenCV.

VP9 in an MP4 container plays in current browsers and is what this OpenCV build can
encode (its FFmpeg has no H.264 encoder); ``mp4v`` (MPEG-4 Part 2) is the fallback where
VP9 is missing: it plays in VLC and most desktop players, not in browsers.
"""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np

log = logging.getLogger(__name__)
CODECS = ("vp09", "mp4v")


class VideoWriter:
    """Write RGB frames to ``path``; the size is taken from the first frame."""

    def __init__(self, path, fps: float):
        self.path = Path(path)
        if self.path.suffix.lower() != ".mp4":
            raise ValueError(f"video path must end in .mp4, got {self.path.name!r}")
        self.fps = fps
        self.frames = 0
        self.codec = None
        self._writer = None
        self._size = None

    def _open(self, width: int, height: int):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        for codec in CODECS:
            writer = cv2.VideoWriter(str(self.path), cv2.VideoWriter_fourcc(*codec), self.fps, (width, height))
            if writer.isOpened():
                if codec != CODECS[0]:
                    log.warning("VP9 is not available; %s uses %s, which browsers may not play", self.path, codec)
                self._writer, self.codec, self._size = writer, codec, (width, height)
                return
        raise RuntimeError(f"OpenCV cannot encode MP4 video here (tried {', '.join(CODECS)})")

    def write(self, frame: np.ndarray):
        frame = np.asarray(frame)
        if frame.ndim != 3 or frame.shape[2] != 3:
            raise ValueError(f"expected an RGB frame (H, W, 3), got shape {frame.shape}")
        h, w = frame.shape[:2]
        frame = np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")  # yuv420: even sizes
        if self._writer is None:
            self._open(frame.shape[1], frame.shape[0])
        elif (frame.shape[1], frame.shape[0]) != self._size:
            raise ValueError(f"frame size {frame.shape[1]}x{frame.shape[0]} differs from the video's {self._size}")
        self._writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
        self.frames += 1

    def close(self):
        if self._writer is not None:
            self._writer.release()
            self._writer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
