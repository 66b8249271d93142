"""Video of a trial: frames rendered through ``Backend.render`` at a fixed simulated rate.

Frames are taken on *simulated* time (frame k shows the world as the first
physics step past ``k / fps`` simulated seconds left it), so the video plays
at the speed the trial happened in simulation however fast the machine
renders, and a trial of D simulated seconds has ``ceil(D * fps)`` frames.
Rendering happens only at frame times, from the runner's step callback; the
physics never waits on anything else, so a result is the same with or
without a video.

Defaults (:data:`VIDEO_SIZE`, :data:`DEFAULT_FPS`): 400 x 300 at 8 frames
per simulated second, which keeps recording under the trial's own CPU time
with PyBullet's CPU renderer, whose cost grows with the pixels drawn
(480 x 360 costs ~1.5x, 640 x 480 ~2.5x as much: BENCHMARKS.md, "Trial video"). The camera is
a *view* (:data:`VIEWS`): ``close`` frames both hands and the cube (a
Rubik's strategy's :meth:`video_camera`, else the workspace in front of the
robot; in-hand: the hand), ``wide`` the whole robot. Each frame carries the
trial, the move being executed ("move 3/5: F'") and the simulated clock in
a box in the top-left corner (:func:`burn_in`).

MP4 is written with ``imageio-ffmpeg``, whose wheel bundles an ffmpeg binary
(no system ffmpeg needed); without it, or for a ``.gif`` path, an animated
GIF is written with Pillow.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..backends.interface import CameraSpec

if TYPE_CHECKING:
    from .contract import TrialContext

__all__ = [
    "DEFAULT_CAMERA",
    "DEFAULT_FPS",
    "VIDEO_SIZE",
    "VIEWS",
    "TrialFilm",
    "VideoSpec",
    "VideoUnavailable",
    "VideoWriter",
    "burn_in",
    "camera_for",
    "rubiks_camera",
]

#: Frame size (width, height) and rate (frames per simulated second) unless asked otherwise.
VIDEO_SIZE = (400, 300)
DEFAULT_FPS = 8.0
#: Camera views ``run --video-view`` offers.
VIEWS = ("close", "wide")

#: Looks at the middle of a PR2-sized workspace from the front right, above the table: the
#: ``wide`` view when nothing better is known.
DEFAULT_CAMERA = CameraSpec(
    eye=(1.6, -1.0, 1.4),
    target=(0.6, 0.0, 0.75),
    width=VIDEO_SIZE[0],
    height=VIDEO_SIZE[1],
    fov_deg=50.0,
)

#: Where a close view looks from, relative to what it looks at: in front of the robot (+x), a
#: little to its right (-y) and above, so both grippers reaching in from the robot face the camera.
_CLOSE_DIRECTION = np.array([0.80, -0.42, 0.43])
_CLOSE_DISTANCE = (
    0.38  # m; with a 40 deg vertical field the 5.7 cm cube is 1/5 to 1/4 of the height
)
_WIDE_DIRECTION = np.array([0.62, -0.45, 0.43])
_WIDE_DISTANCE = 1.45


def _xyz(v: Any) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])


class VideoUnavailable(RuntimeError):
    """The video cannot be made (no renderer, no writer)."""


@dataclass(frozen=True)
class VideoSpec:
    """Which trial to film, where, how. ``camera`` ``None``: the ``view`` (:func:`camera_for`)."""

    path: Path
    trial_index: int = 1
    fps: float = DEFAULT_FPS
    camera: CameraSpec | None = None
    view: str = "close"
    size: tuple[int, int] = VIDEO_SIZE  #: width, height of a view's camera
    overlay: bool = True  #: burn the move and clock into each frame

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))
        if not (self.fps > 0 and math.isfinite(self.fps)):
            raise ValueError("video fps must be a positive finite number")
        if self.view not in VIEWS:
            raise ValueError(f"video view {self.view!r}: one of {', '.join(VIEWS)}")
        w, h = self.size
        if w < 16 or h < 16:
            raise ValueError(f"video size {w}x{h}: at least 16x16")


def rubiks_camera(
    target: Sequence[float], view: str = "close", size: tuple[int, int] = VIDEO_SIZE
) -> CameraSpec:
    """A camera on a Rubik's workspace whose cube is held around ``target`` (robot base frame).

    ``close``: 0.38 m from the target, 40 deg vertical field, so the cube is
    about a quarter of the frame's height and both grippers holding it are in
    view; ``wide``: 1.45 m back, 50 deg, the robot's arms and torso.
    """
    t = np.asarray(target, dtype=float)
    if view == "close":
        d, dist, fov = _CLOSE_DIRECTION, _CLOSE_DISTANCE, 40.0
    elif view == "wide":
        d, dist, fov, t = _WIDE_DIRECTION, _WIDE_DISTANCE, 50.0, t + [0.0, 0.0, 0.15]
    else:
        raise ValueError(f"video view {view!r}: one of {', '.join(VIEWS)}")
    eye = t + dist * d / np.linalg.norm(d)
    return CameraSpec(
        _xyz(eye),
        _xyz(t),
        width=int(size[0]),
        height=int(size[1]),
        fov_deg=fov,
        near=0.02,
        far=6.0,
    )


def _inhand_camera(ctx: TrialContext, view: str, size: tuple[int, int]) -> CameraSpec | None:
    """The hand, seen from above in front: close 0.4 m away, wide 1.0 m."""
    body = getattr(ctx.robot, "body", None)
    if body is None:
        return None
    try:
        base = ctx.backend.get_link_pose(body, None).p
    except Exception:  # noqa: BLE001 - not spawned (yet): the caller falls back
        return None
    dist = 0.4 if view == "close" else 1.0
    d = np.array([0.75, -0.45, 0.55])
    eye = base + dist * d / np.linalg.norm(d)
    return CameraSpec(
        _xyz(eye),
        _xyz(base),
        width=int(size[0]),
        height=int(size[1]),
        fov_deg=45.0,
    )


def camera_for(spec: VideoSpec, strategy: Any, ctx: TrialContext | None) -> CameraSpec:
    """The camera a video uses: ``spec.camera``; else the strategy's ``video_camera(view, size)``
    (or a ``video_camera`` :class:`CameraSpec` attribute, for every view); else an in-hand trial's
    view of the hand; else a Rubik's view of a PR2-sized workspace (:func:`rubiks_camera`)."""
    if spec.camera is not None:
        return spec.camera
    own = getattr(strategy, "video_camera", None)
    if isinstance(own, CameraSpec):
        return own
    if callable(own):
        cam = own(spec.view, spec.size)
        if isinstance(cam, CameraSpec):
            return cam
    if ctx is not None and hasattr(ctx.item, "task_set"):
        cam = _inhand_camera(ctx, spec.view, spec.size)
        if cam is not None:
            return cam
    if spec.view == "wide":
        return replace(DEFAULT_CAMERA, width=spec.size[0], height=spec.size[1])
    return rubiks_camera((0.6, 0.0, 0.58), spec.view, spec.size)


# -- the overlay -----------------------------------------------------------------------------------
@lru_cache(maxsize=4)
def _font(px: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=px)
    except TypeError:  # Pillow < 10.1: the fixed bitmap font
        return ImageFont.load_default()


def burn_in(frame: np.ndarray, lines: Sequence[str]) -> np.ndarray:
    """``frame`` with ``lines`` of text in a dark box in its top-left corner (white on black).

    The text is 1/20 of the frame's height (15 px at 300), so it stays
    readable after the MP4's compression; the box covers only the text.
    """
    if not lines:
        return frame
    from PIL import Image, ImageDraw

    img = Image.fromarray(np.ascontiguousarray(frame[..., :3], dtype=np.uint8))
    draw = ImageDraw.Draw(img)
    px = max(12, img.height // 20)
    font = _font(px)
    pad, gap = px // 2, px // 4
    widths = [draw.textlength(s, font=font) for s in lines]
    box_w = int(max(widths)) + 2 * pad
    box_h = len(lines) * px + (len(lines) - 1) * gap + 2 * pad
    draw.rectangle((0, 0, box_w, box_h), fill=(0, 0, 0))
    for i, s in enumerate(lines):
        draw.text((pad, pad + i * (px + gap)), s, fill=(255, 255, 255), font=font)
    return np.asarray(img)


class _Overlay:
    """The text of each frame, from the trial's item and what the recorder has logged so far."""

    def __init__(self, ctx: TrialContext) -> None:
        self.ctx = ctx
        item = ctx.item
        self.sequence: tuple[Any, ...] | None = getattr(item, "sequence", None)
        if self.sequence is not None:
            self.title = f"{item.tier} trial {item.trial}"  # type: ignore[union-attr]
        else:
            self.title = f"{getattr(item, 'task_set', 'task')} {getattr(item, 'task_id', '')}"
        self._seen = 0
        self._moves_done = 0
        self._action = ""

    def lines(self) -> list[str]:
        rec = self.ctx.recorder
        events = rec.events
        for e in events[self._seen :]:  # incremental: the log only grows
            if e["kind"] == "move":
                self._moves_done += 1
            elif e["kind"] == "action":
                self._action = str(e.get("action", "")).lower()
        self._seen = len(events)
        t = float(self.ctx.backend.time) - self.ctx.sim_start
        clock = f"t = {t:.2f} s"
        if rec.first_contact_s is not None:
            clock += f", since contact {t + self.ctx.sim_start - rec.first_contact_s:.2f} s"
        out = [self.title]
        if self.sequence is not None:
            n = len(self.sequence)
            k = self._moves_done
            if k < n:
                doing = f" ({self._action})" if self._action else ""
                out.append(f"move {k + 1}/{n}: {self.sequence[k]}{doing}")
            else:
                out.append(f"{n}/{n} moves done" + (f" ({self._action})" if self._action else ""))
        out.append(clock)
        return out


# -- writing ---------------------------------------------------------------------------------------
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
                    # the encoder's own threads would compete with the physics for the CPU
                    output_params=["-preset", "ultrafast", "-threads", "1"],
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


class TrialFilm:
    """One trial's video: called after every physics step, renders only when a frame is due.

    The camera is resolved at the first frame (the strategy has built its
    scene by then, so an in-hand view can find the hand). Frame ``k`` is due
    once simulated time has passed ``k / fps`` since the trial's start; a
    step longer than a frame interval repeats the frame it rendered.
    """

    def __init__(
        self,
        spec: VideoSpec,
        ctx: TrialContext,
        strategy: Any = None,
        writer_factory: Callable[[Path, float, tuple[int, int]], VideoWriter] = VideoWriter,
    ) -> None:
        self.spec, self.ctx, self.strategy = spec, ctx, strategy
        self._factory = writer_factory
        self.writer: VideoWriter | None = None
        self.camera: CameraSpec | None = None
        self._overlay = _Overlay(ctx) if spec.overlay else None
        self._frames = 0
        self.render_s = 0.0  #: process CPU seconds spent rendering, drawing and encoding

    def after_step(self) -> None:
        t = float(self.ctx.backend.time) - self.ctx.sim_start
        due = math.ceil(t * self.spec.fps - 1e-6)  # frames 0 .. due-1 are due
        if due <= self._frames:
            return
        import time

        c0 = time.process_time()
        if self.camera is None:
            self.camera = camera_for(self.spec, self.strategy, self.ctx)
            self.writer = self._factory(
                self.spec.path, self.spec.fps, (self.camera.width, self.camera.height)
            )
        assert self.writer is not None
        frame = self.ctx.backend.render(self.camera)
        if self._overlay is not None:
            frame = burn_in(frame, self._overlay.lines())
        while self._frames < due:
            self.writer.write(frame)
            self._frames += 1
        self.render_s += time.process_time() - c0

    @property
    def frames_written(self) -> int:
        return 0 if self.writer is None else self.writer.frames_written

    def info(self) -> dict[str, Any]:
        w = self.writer
        return {
            "path": str(w.path if w is not None else self.spec.path),
            "frames": self.frames_written,
            "fps": self.spec.fps,
            "view": self.spec.view,
            "size": None if self.camera is None else [self.camera.width, self.camera.height],
            "render_cpu_s": round(self.render_s, 3),
            "note": "" if w is None else w.note,
        }

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
