"""What a twist did, measured; and why a twist could not start."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cube.facelets import to_string

__all__ = ["TwistBlockedError", "TwistOutcome"]


class TwistBlockedError(RuntimeError):
    """A twist about ``axis`` cannot start because the cube is articulated about ``blocking_axis``.

    ``misaligned`` is True when that is a layer left beyond the snap tolerance
    (a real cube jams the same way), False when a twist is merely still open.
    """

    def __init__(
        self, axis: str, blocking_axis: str, layer_angles_deg: tuple[float, float], misaligned: bool
    ) -> None:
        self.axis = axis
        self.blocking_axis = blocking_axis
        self.layer_angles_deg = layer_angles_deg
        self.misaligned = misaligned
        a0, a2 = layer_angles_deg
        if misaligned:
            msg = (
                f"misaligned layer blocks rotation about axis {axis}: the cube's layers about axis "
                f"{blocking_axis} stand at {a0:.1f}° and {a2:.1f}° relative to the middle layer, "
                "beyond the snap tolerance of a quarter turn"
            )
        else:
            msg = (
                f"a twist about axis {blocking_axis} is still open (layers at {a0:.1f}°, {a2:.1f}°); "
                f"call end_twist() before rotating about axis {axis}"
            )
        super().__init__(msg)


@dataclass(frozen=True)
class TwistOutcome:
    """The measured result of one twist (one :meth:`PhysicalCube.end_twist` call).

    Layer angles are rotations about the body's +axis relative to the middle
    slab (slab 1), so ``layer_angles_deg[1]`` is 0 by definition. The flags
    that need an intention are ``None`` when the caller did not name one.
    """

    axis: str
    intended: str | None
    layer_angles_deg: tuple[float, float, float]  #: measured, slabs 0, 1, 2
    quarter_turns: tuple[int, int, int]  #: nearest multiple of 90° of each layer angle
    residuals_deg: tuple[float, float, float]
    moves: str  #: face moves applied to the logical state ("" if none or misaligned)
    state_updated: bool
    misaligned: bool  #: a layer is beyond the snap tolerance; the cube stays articulated
    #: rotation of the intended layer relative to the held one, along the intended direction (deg)
    turned_deg: float | None
    #: rotation of the layer(s) meant to stay with the held one, relative to it (deg)
    dragged_deg: float | None
    unintended_rotation: bool | None  #: a layer meant to stay still moved beyond the tolerance
    jammed: bool | None  #: the intended layer turned less than the jam threshold
    as_intended: (
        bool | None
    )  #: logical result equals the core's result of ``intended`` (up to a whole-cube rotation)
    state_before: np.ndarray
    state_after: np.ndarray

    @property
    def state_before_string(self) -> str:
        return to_string(self.state_before)

    @property
    def state_after_string(self) -> str:
        return to_string(self.state_after)

    def summary(self) -> str:
        a0, _, a2 = self.layer_angles_deg
        flags = [n for n in ("misaligned", "unintended_rotation", "jammed") if getattr(self, n)]
        return (
            f"twist about {self.axis} (intended {self.intended or '-'}): layers {a0:+.1f}° / {a2:+.1f}° "
            f"-> moves {self.moves or '(none)'}" + (f" [{', '.join(flags)}]" if flags else "")
        )
