"""Settings of the in-grasp trajectory optimiser and the five Level I variants.

Weights are per squared residual, with positions in metres and rotations in
radians (rotation residuals are ``sin(angle) * axis``); 1 cm of position
weighs as much as ~5.7 deg of orientation throughout. One rule sets the
relaxed variants' weights: a metre of fingertip slip against the object
(per waypoint and finger) weighs as much as a metre of goal error, so the
rigidity, summed over the waypoints and fingers, dominates the one goal term.
The papers' own weights were not available to us (docs/ingrasp.md).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["VARIANTS", "RELAXED", "OBJECT_PATH", "IngraspConfig"]

#: Variants whose object pose is implied by the reference fingertip and whose
#: grasp is kept by a *cost* on how the other fingertips move against the object.
RELAXED = ("relaxed-rigidity", "relaxed-position", "relaxed-position-orientation")
#: Variants that track an object path (interpolated initial -> goal) with
#: every fingertip as a hard-ish rigid (pose) or point (position) contact.
OBJECT_PATH = ("ik-rigid", "point-contact")
VARIANTS = RELAXED + OBJECT_PATH


@dataclass(frozen=True)
class IngraspConfig:
    """One optimisation problem's settings (all variants share them)."""

    waypoints: int = 10  #: T, joint waypoints after the (fixed) initial grasp
    duration_s: float = 1.67  #: execution time the trajectory is timed for (paper IV-A2)
    max_joint_speed: float = 1.0  #: rad/s; with duration/T gives the per-step bound |q_t - q_{t-1}|
    #: How the object pose follows from the fingertips: ``"fingertips"`` (attached to the frame of
    #: the fingertip triangle: centroid, edge, normal; ours, the default) or ``"reference-finger"``
    #: (attached to the first fingertip's frame, as in the original). With our Allegro kinematics a
    #: single 4-joint finger cannot carry the object to the published goals (median 1.3 cm short
    #: at best), see docs/ingrasp.md.
    object_frame: str = "fingertips"
    # All weights multiply squared residuals in SI units (m, rad). One rule sets them: a metre of
    # fingertip slip against the object weighs as much as a metre of object pose error, and a
    # radian as much as 10 cm (1 cm ~ 5.7 deg). The rigidity terms are summed over the T waypoints
    # and the fingers, the goal term is one pose: keeping the grasp outweighs the last millimetres
    # of goal (the relaxed rigidity acts as the near-constraint its name says). docs/ingrasp.md.
    #: the goal cost at every waypoint (True) or at the last only (False, default): every waypoint
    #: pulled to an unreachable-yet goal stretches the grasp (measured, docs/ingrasp.md)
    goal_every_waypoint: bool = False
    w_goal_pos: float = 1.0e4  #: object position at the last waypoint vs goal (m^2)
    w_goal_rot: float = 1.0e2  #: object orientation at the last waypoint vs goal (rad^2)
    #: relaxed rigidity: fingertip position in the object frame vs its initial one, per waypoint and finger
    w_rigid_pos: float = 1.0e4
    #: relaxed-position-orientation only: fingertip orientation relative to the object, likewise
    w_rigid_rot: float = 1.0e2
    # object-path variants: fingertip targets on the interpolated object path ("constraints")
    w_contact_pos: float = 1.0e6
    w_contact_rot: float = 1.0e4
    #: joint-velocity smoothness, sum of squared joint steps (rad^2): a 0.1 rad step weighs as much
    #: as 0.1 mm of goal error, so it only chooses among trajectories that keep the grasp equally well
    w_smooth: float = 1.0e-2
    w_limits: float = (
        1.0e5  #: squared violation of joint and step limits (rad^2), before the final projection
    )
    #: hand-object collision, our extension (0 = off, the default): in simulated trials, the squared
    #: shortfall (m^2) of each hand part's distance to the object below its allowed distance, per
    #: waypoint and part (strategies/ingrasp/collision.py). The Autonomous Robots 2019 method's
    #: signed-distance cost keeps the object off its *environment*, of which a Level I task in
    #: free space has none, so the published method plans without it. 1e6 weighs it as the
    #: object-path variants' contact constraints. Measured effect: docs/ingrasp.md "Collision term"
    w_collision: float = 0.0
    #: m, the distance every hand shape other than the used fingertips keeps from the object (or
    #: its distance at the initial grasp, if smaller): the set-up placement's clearance
    collision_margin: float = 0.001
    #: object surface samples the collision term uses (every n-th mesh vertex)
    collision_points: int = 600
    #: ``"trf"``: bounded trust-region least squares on the residuals (scipy, exact Jacobian; the
    #: default); ``"lm"``: in-house Levenberg-Marquardt; ``"lbfgs"``: L-BFGS on the sum of squares
    #: (the default before 2026-12-02, which stopped short). docs/ingrasp.md "Solver"
    solver: str = "trf"
    #: initial trajectory: ``"ik"`` (joints interpolated from ``q0`` to an IK solution of the
    #: fingertips carried rigidly to the goal) or ``"constant"`` (``q0`` at every waypoint)
    init: str = "ik"
    #: solver iterations in all (L-BFGS iterations; LM: Jacobian evaluations; trf: residual evaluations)
    max_iterations: int = 150
    inner_iterations: int = (
        25  #: L-BFGS only: iterations per call; convergence is checked between calls
    )
    ftol: float = (
        1.0e-6  #: relative cost decrease of one call (L-BFGS) or iteration (LM): converged
    )
    xtol: float = 1.0e-10  #: trf only: relative step size below which it is converged
    gtol: float = 1.0e-7  #: gradient max-norm below which the optimiser is converged
    init_noise: float = 1.0e-4  #: rad, seeded perturbation of the constant initial trajectory
    seed: int = 0  #: seed of that perturbation (torch.Generator); same seed, same trajectory
    limit_margin: float = 0.0  #: rad kept inside the URDF joint limits

    def __post_init__(self) -> None:
        if self.waypoints < 1:
            raise ValueError("waypoints must be >= 1")
        if self.object_frame not in ("reference-finger", "fingertips"):
            raise ValueError(
                f"object_frame must be 'reference-finger' or 'fingertips', not {self.object_frame!r}"
            )
        if self.solver not in ("trf", "lm", "lbfgs"):
            raise ValueError(f"solver must be 'trf', 'lm' or 'lbfgs', not {self.solver!r}")
        if self.init not in ("ik", "constant"):
            raise ValueError(f"init must be 'ik' or 'constant', not {self.init!r}")
        for name in ("w_collision", "collision_margin"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0, not {getattr(self, name)!r}")
        if self.collision_points < 1:
            raise ValueError(f"collision_points must be >= 1, not {self.collision_points!r}")
        if self.duration_s <= 0 or self.max_joint_speed <= 0:
            raise ValueError("duration_s and max_joint_speed must be positive")

    @property
    def max_step(self) -> float:
        """Largest joint change between consecutive waypoints (rad)."""
        return self.max_joint_speed * self.duration_s / self.waypoints
