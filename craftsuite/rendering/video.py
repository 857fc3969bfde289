"""MP4 rollout videos: H.264 in yuv420p, through the FFmpeg that imageio-ffmpeg ships.

H.264 with 4:2:0 chroma is the one MP4 flavour that browsers, QuickTime, phones and
desktop players all decode. yuv420p stores colour at half resolution, so both sides of a
frame must be even: odd frames are padded by one row or column (repeating the edge),
never scaled, so every pixel of the world stays where the env drew it.
"""

from __future__ import annotations

from pathlib import Path

import imageio_ffmpeg
import numpy as np

CODEC = "h264"  # what the file holds (the encoder is FFmpeg's libx264)
_ENCODER = "libx264"
_PIXEL_FORMAT = "yuv420p"


def even_frame(frame: np.ndarray) -> np.ndarray:
    """``frame`` padded by its last row / column where a side is odd (yuv420p needs even sides)."""
    h, w = frame.shape[:2]
    if h % 2 or w % 2:
        frame = np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
    return frame


def check_video_path(path) -> Path:
    """``path`` as a video's file: MP4, by its name (``VideoWriter``'s one format).

    Raises:
        ValueError: a name not ending in .mp4, with one that does.
    """
    path = Path(path)
    if path.suffix.lower() != ".mp4":
        raise ValueError(f"{path}: a video is written as MP4; give a file name ending in .mp4, e.g. "
                         f"{path.with_suffix('.mp4') if path.name else path / 'rollout.mp4'}")
    return path


class VideoWriter:
    """Write RGB frames to ``path``; the size is taken from the first frame (padded to even
    sides), and every later frame must have the same size."""

    def __init__(self, path, fps: float):
        self.path = check_video_path(path)
        if not fps > 0:
            raise ValueError(f"fps must be positive, got {fps!r}")
        self.path.parent.mkdir(parents=True, exist_ok=True)  # a folder that cannot be made fails before any frame
        self.fps = fps
        self.frames = 0
        self.codec = CODEC
        self.size: tuple[int, int] | None = None  # (width, height) of the file
        self._encoder = None

    def _open(self, width: int, height: int):
        self._encoder = imageio_ffmpeg.write_frames(
            str(self.path), (width, height), fps=float(self.fps), codec=_ENCODER,
            pix_fmt_in="rgb24", pix_fmt_out=_PIXEL_FORMAT,
            macro_block_size=2,  # sides are even already: imageio must not rescale
            output_params=["-movflags", "+faststart"],  # playable while it downloads
        )
        self._encoder.send(None)  # starts FFmpeg
        self.size = (width, height)

    def write(self, frame: np.ndarray):
        frame = np.asarray(frame)
        if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
            raise ValueError(f"expected an RGB frame (H, W, 3) of uint8, got shape {frame.shape} of {frame.dtype}")
        frame = even_frame(frame)
        size = (frame.shape[1], frame.shape[0])
        if self._encoder is None:
            self._open(*size)
        elif size != self.size:
            raise ValueError(f"frame size {size[0]}x{size[1]} differs from the video's {self.size[0]}x{self.size[1]}")
        self._encoder.send(np.ascontiguousarray(frame))
        self.frames += 1

    def close(self):
        if self._encoder is not None:
            self._encoder.close()  # waits for FFmpeg to finish the file
            self._encoder = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
