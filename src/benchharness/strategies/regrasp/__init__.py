"""Regrasp/twist planner: from a move sequence to bimanual grasps, hand-overs and twists.

Pure logic, no physics: a library for the Rubik's cube baselines (dead
reckoning, pre-touch, push-grasp), not a registered strategy — no module here
defines ``REGISTRATIONS``. Modules, each named for what it holds:

* :mod:`.orientation` — the cube's 24 orientations in the workspace;
* :mod:`.model` — work axis, grips, wrist range, costs (:class:`HandModel`);
* :mod:`.translate` — notation (incl. slices and rotations) → centre-named face twists;
* :mod:`.actions` — :class:`Pick`, :class:`Twist`, :class:`Regrasp`, :class:`Handover`,
  :class:`Release` and the :class:`RegraspPlan`;
* :mod:`.search` — :func:`plan_sequence` (A*, optimal for the cost model) and :func:`naive_plan`;
* :mod:`.executor` — :func:`execute`: the plan on the logical cube, every rule checked.

See docs/planner.md.
"""

from .actions import Action, Handover, Pick, Regrasp, RegraspPlan, Release, Twist
from .executor import Execution, PlanError, TwistCheck, execute, twist_move
from .model import CostModel, Grip, HandModel
from .orientation import INITIAL_ORIENTATION, Orientation, all_orientations
from .search import RegraspNoPlanError, naive_plan, plan_sequence
from .translate import FaceTwist, MoveTwists, logical_twists

__all__ = [
    "Action",
    "CostModel",
    "Execution",
    "FaceTwist",
    "Grip",
    "HandModel",
    "Handover",
    "INITIAL_ORIENTATION",
    "MoveTwists",
    "RegraspNoPlanError",
    "Orientation",
    "Pick",
    "RegraspPlan",
    "PlanError",
    "Regrasp",
    "Release",
    "Twist",
    "TwistCheck",
    "all_orientations",
    "execute",
    "logical_twists",
    "naive_plan",
    "plan_sequence",
    "twist_move",
]
