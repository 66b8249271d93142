"""The physical Rubik's cube: a mechanism whose twists come out of contact physics.

* :mod:`.config` — :class:`CubeConfig`, every parameter with its default and why;
* :mod:`.model` — body frame, facelet geometry, slab mass properties, the generated URDF;
* :mod:`.layers` — snapping measured angles and turning layer quarter turns into moves;
* :mod:`.outcome` — :class:`TwistOutcome` and :class:`TwistBlockedError`;
* :mod:`.mechanism` — :class:`PhysicalCube`, the rigid ↔ three-slab swap on a Backend.

See docs/cube_physics.md. Nothing here imports a physics engine.
"""

from .config import CubeConfig
from .layers import IntendedTwist, SnappedAngle, intended_twist, layer_moves, snap_angle
from .mechanism import PhysicalCube
from .model import AXIS_FACES, AXIS_SLICES, FACE_BODY_AXES, FACELET_BODY_POSITIONS, articulated_urdf
from .outcome import TwistBlockedError, TwistOutcome

__all__ = [
    "AXIS_FACES",
    "AXIS_SLICES",
    "CubeConfig",
    "FACELET_BODY_POSITIONS",
    "FACE_BODY_AXES",
    "IntendedTwist",
    "PhysicalCube",
    "SnappedAngle",
    "TwistBlockedError",
    "TwistOutcome",
    "articulated_urdf",
    "intended_twist",
    "layer_moves",
    "snap_angle",
]
