"""Video of a trial: frames rendered through ``Backend.render`` at a fixed simulated rate.

Frames are taken on *simulated* time (every ``1/fps`` simulated seconds), so
the video plays at the speed the trial happened in simulation however fast
the machine renders. MP4 is written with ``imageio-ffmpeg``, whose wheel
bundles an ffmpeg binary (no system ffmpeg needed); without it, or for a
``.gif`` path, an animated GIF is written with Pillow.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..backends.interface import CameraSpec

__all__ = ["VideoSpec", "VideoWriter", "VideoUnavailable", "DEFAULT_CAMERA"]

#: Looks at the middle of a PR2-sized workspace from the front right, above the table.
DEFAULT_CAMERA = CameraSpec(
    eye=(1.6, -1.0, 1.4), target=(0.6, 0.0, 0.75), width=480, height=360, fov_deg=50.0
)


class VideoUnavailable(RuntimeError):
    """The video cannot be made (no renderer, no writer)."""


@dataclass(frozen=True)
class VideoSpec:
    """Which trial to film, where, how. ``camera`` ``None``: the strategy's
    ``video_camera`` attribute if it has one, else :data:`DEFAULT_CAMERA`."""

    path: Path
    trial_index: int = 1
    fps: float = 30.0
    camera: CameraSpec | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))
        if self.fps <= 0:
            raise ValueError("video fps must be positive")


def _has_ffmpeg() -> bool:
    try:
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass
class VideoWriter:
    """Streams frames to disk (MP4 via imageio-ffmpeg, else GIF via Pillow)."""

    path: Path
    fps: float
    size: tuple[int, int]  # width, height
    frames_written: int = 0
    note: str = ""
    _gen: Any = field(default=None, repr=False)
    _gif: list = field(default_factory=list, repr=False)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.path.suffix.lower() != ".gif":
            if _has_ffmpeg():
                import imageio_ffmpeg

                w, h = self.size
                self._gen = imageio_ffmpeg.write_frames(
                    str(self.path),
                    (w, h),
                    fps=self.fps,
                    codec="libx264",
                    pix_fmt_out="yuv420p",
                    macro_block_size=2,
                    quality=7,
                    ffmpeg_log_level="error",
                )
                self._gen.send(None)
            else:
                gif = self.path.with_suffix(".gif")
                self.note = (
                    f"imageio-ffmpeg is not installed, so {self.path.name} could not be written as MP4; "
                    f"wrote an animated GIF to {gif} instead (pip install imageio-ffmpeg for MP4)"
                )
                warnings.warn(self.note, stacklevel=2)
                self.path = gif

    def write(self, frame: np.ndarray) -> None:
        frame = np.ascontiguousarray(np.asarray(frame)[..., :3], dtype=np.uint8)
        if self._gen is not None:
            self._gen.send(frame)
        else:
            self._gif.append(frame)
        self.frames_written += 1

    def close(self) -> None:
        if self._gen is not None:
            self._gen.close()
            self._gen = None
        elif self._gif:
            from PIL import Image

            images = [Image.fromarray(f) for f in self._gif]
            images[0].save(
                self.path,
                save_all=True,
                append_images=images[1:],
                duration=max(1, round(1000 / self.fps)),
                loop=0,
            )
            self._gif = []
