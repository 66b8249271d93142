"""The push-grasp primitive on a BarrettHand (Yang et al. 2020, Sec. IV-D, Fig. 3; Dogar & Srinivasa 2011).

A push grasp turns pose uncertainty along the approach into a contact event:
the hand is pre-shaped so that one finger (the "middle finger", BarrettHand
finger 3, the thumb) sticks out in front of the palm as a probe, the hand
moves along the face normal at a slow constant speed, and it stops as soon
as the probe (or any hand link) touches the cube with at least
``contact_force`` newtons, as the engine's contact report says. The hand is
then at a known depth relative to the face, whatever the belief said; the
outer fingers (F1 and F2, spread 90 deg so that they face each other across
the face) close on the cube's side faces to finish the grasp.

Nothing here reads the cube's true pose: the stop comes from contact reports
between the robot's hand links and the cube body (what a real hand gets
from strain gauges or motor currents), and the travel returned is the
travel measured by the arm's joint encoders (forward kinematics of the measured
joints), which is what the strategy can know.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...geometry import Pose

#: joint-name suffixes of the two outer fingers (F1, F2: proximal and distal)
OUTER_FINGER_JOINTS = ("_bh_j12_joint", "_bh_j13_joint", "_bh_j22_joint", "_bh_j23_joint")
#: joint-name suffixes of the thumb (F3)
THUMB_JOINTS = ("_bh_j32_joint", "_bh_j33_joint")

__all__ = [
    "OUTER_FINGER_JOINTS",
    "THUMB_JOINTS",
    "PushResult",
    "PushUnreachable",
    "close_outer_fingers",
    "preshape",
    "push_until_contact",
    "wait_fingers",
]


class PushUnreachable(RuntimeError):
    """The straight push path has a waypoint without an IK solution."""


@dataclass(frozen=True)
class PushResult:
    """What one push along the approach achieved."""

    contact: bool  #: the hand touched the object before the push limit
    travel: float  #: m travelled along the approach until the stop, from the joint encoders (FK)
    commanded: Pose  #: the believed tool pose at the stop: ``start`` moved by ``travel`` along the approach
    links: tuple[str, ...]  #: hand links in contact at the stop
    force: float  #: N, summed normal force of those contacts at the stop
    time: float  #: s simulated


def _hand_links(robot, hand) -> set[str]:
    """The hand's links: every link whose joint belongs to the hand, plus the palm (the tool link's parent)."""
    links = set(hand.config.finger_links)
    for j in hand.joints:
        links.add(robot.urdf_joints[j].child)
    palm = hand.config.tcp_link.replace("_tcp", "_palm_link")
    if palm in robot.link_names:
        links.add(palm)
    return links


def contact_force(robot, hand, obj, links: set[str] | None = None) -> tuple[float, tuple[str, ...]]:
    """Summed normal force (N) between ``links`` of the hand (default: all) and ``obj``, and the links touching."""
    links = links if links is not None else _hand_links(robot, hand)
    total, hit = 0.0, set()
    for c in robot.backend.contacts(robot.body, obj):
        if c.link_a in links:
            total += float(c.normal_force)
            hit.add(c.link_a)
    return total, tuple(sorted(hit))


def preshape(
    hand,
    spread: float,
    thumb_flex: float,
    *,
    outer_flex: float = 0.0,
    wait: float = 0.4,
    thumb_force: float = 2.0,
) -> None:
    """Open F1 and F2 to ``outer_flex``, set the spread, flex the thumb (F3) to ``thumb_flex`` rad: the probe."""
    u = np.array([spread, outer_flex, outer_flex, thumb_flex])
    f = np.asarray(hand.config.force_limit, dtype=float).copy()
    # the thumb probes: its drive may push harder than a grasping finger so that it does not fold on contact
    for i, j in enumerate(hand.joints):
        if j.endswith(THUMB_JOINTS):
            f[i] = max(f[i], thumb_force)
    hand.set_command(u, f)
    wait_fingers(hand, wait)


def _force_limits(hand) -> np.ndarray:
    """The joint force caps last commanded to ``hand`` (the config's if the gripper does not expose them)."""
    return np.asarray(getattr(hand, "_force", hand.config.force_limit), dtype=float)


def wait_fingers(hand, timeout: float, *, rest_speed: float = 0.02, min_time: float = 0.1) -> float:
    """Step until the hand's joints have been at rest 0.1 s (or ``timeout``); returns s simulated."""
    r = hand.robot
    dt = r.backend.config.timestep
    chunk = max(1, int(round(0.02 / dt)))
    t, rest = 0.0, 0.0
    names = list(hand.joints)
    while t < timeout:
        r.step(chunk)
        t += chunk * dt
        v = r.joint_velocities(names)
        rest = rest + chunk * dt if np.max(np.abs(v)) < rest_speed else 0.0
        if rest >= 0.1 and t >= min_time:
            break
    return t


def close_outer_fingers(
    hand,
    force_limit: float,
    *,
    speed: float = 1.5,
    timeout: float = 2.5,
    closed: float | None = None,
    stall: float = 0.12,
    centre: bool = True,
) -> float:
    """Close F1 and F2 (facing each other at spread 90 deg), keeping the spread and the thumb.

    The command ramps at ``speed`` rad/s instead of jumping to "closed": a
    BarrettHand finger closes at about 1-2 rad/s, and a jump lets the light
    finger links hit the cube at tens of rad/s on PyBullet, which knocks it
    away. Once both proximal joints lag their ramping command by ``stall``
    rad (the fingers are on the cube):

    * ``centre`` (default): both fingers are re-aimed at the *mean* of their
      measured proximal angles plus a spring squeeze ``force_limit / k``, with
      the cap at 1.5 x ``force_limit``: two unsaturated springs about the
      symmetric closure, which push the cube back to the middle if it moves
      (two saturated fingers are two constant forces with no centring, and on
      PyBullet the weaker-yielding finger lets the cube drift ~1 cm);
    * otherwise the command goes to fully closed (each finger presses with
      its capped torque).

    Returns s simulated.
    """
    r = hand.robot
    dt = r.backend.config.timestep
    per = max(1, int(round(r.control_period / dt)))
    tick = per * dt
    u = hand.command.copy()
    target = hand.config.closed[1] if closed is None else closed
    f = np.asarray(_force_limits(hand), dtype=float).copy()  # keep the thumb's probing force
    prox, k = [], []
    for i, j in enumerate(hand.joints):
        if j.endswith(OUTER_FINGER_JOINTS):
            f[i] = force_limit
        if j.endswith(("_bh_j12_joint", "_bh_j22_joint")):
            prox.append(i)
            k.append(hand.config.stiffness[i])
    t = 0.0
    stalled = False
    while t < timeout and u[1] < target:
        u[1] = u[2] = min(target, u[1] + speed * tick)
        hand.set_command(u, f)
        r.step(per)
        t += tick
        q = r.joint_positions(list(hand.joints))
        if all(u[1] - q[i] > stall for i in prox):
            stalled = True
            break
    if centre and stalled:
        q = r.joint_positions(list(hand.joints))
        u[1] = u[2] = float(np.mean(q[prox])) + force_limit / float(np.mean(k))
        for i, j in enumerate(hand.joints):
            if j.endswith(OUTER_FINGER_JOINTS):
                f[i] = 1.5 * force_limit
    else:
        u[1] = u[2] = target
    hand.set_command(u, f)
    return t + wait_fingers(hand, 0.5)


def push_until_contact(
    robot,
    arm,
    hand,
    obj,
    start: Pose,
    *,
    send_offset=None,
    limit: float,
    speed: float,
    force_threshold: float,
    waypoint_spacing: float = 0.005,
    probe_links: Sequence[str] | None = None,
    max_joint_step: float = 0.6,
) -> PushResult:
    """Move the tool frame from ``start`` along its own +z (the approach) until contact or ``limit`` m.

    ``start`` and the returned ``commanded`` pose are *commanded* (believed)
    poses; ``send_offset(pose) -> pose`` maps a commanded pose to what the arm
    is actually sent (the strategy's injected calibration), identity if None.
    The path is a chain of IK solutions every ``waypoint_spacing`` m, each
    seeded with the previous one and no joint moving more than
    ``max_joint_step`` rad between two (else :class:`PushUnreachable`), tracked at ``speed`` m/s with position + velocity PD
    targets every control tick; after every tick the engine's contact report
    between the hand's links and ``obj`` is read, and at ``force_threshold``
    N the arm is held where it is measured to be.
    """
    send = send_offset or (lambda p: p)
    n = max(1, int(np.ceil(limit / waypoint_spacing)))
    d = np.linspace(0.0, limit, n + 1)
    z = start.rotation.apply([0.0, 0.0, 1.0])
    cmd_poses = [Pose(start.p + s * z, start.q) for s in d]
    base = arm.base_pose()
    targets = np.stack([(base.inv() * send(p)).as_matrix() for p in cmd_poses])
    q_now = arm.positions()
    # each waypoint seeded with the previous one, and checked to stay on its branch: a converged IK from a
    # random restart can be a different arm configuration, and the arm would swing there (seen on SAPIEN)
    qs = [q_now]
    for k in range(1, n + 1):
        res = arm.ik(targets[k][None], seed_q=qs[-1])
        jump = float(np.max(np.abs(res.q[0] - qs[-1])))
        if not bool(res.success[0]) or jump > max_joint_step:
            raise PushUnreachable(
                f"no IK solution near the arm's branch at {1000 * d[k]:.0f} mm of the push "
                f"(joint step {jump:.2f} rad)"
            )
        qs.append(res.q[0])
    qs = np.asarray(qs)
    be = robot.backend
    dt = be.config.timestep
    per = max(1, int(round(robot.control_period / dt)))
    tick = per * dt
    links = set(probe_links) if probe_links is not None else _hand_links(robot, hand)
    joints = list(arm.joints)
    duration = limit / speed
    n_ticks = int(np.ceil(duration / tick))
    t0 = be.time

    def measured_travel() -> float:
        """Travel along the approach from the joint encoders (FK of measured joints, start vs now).

        Why not the reference: under PD tracking the arm lags the moving
        reference by a few millimetres, and a real robot knows where its
        joints are, not where the reference was.
        """
        p = arm.fk(arm.positions()[None])[0][:3, 3]
        return float(np.dot(base.rotation.apply(p - p0), z))

    p0 = arm.fk(q_now[None])[0][:3, 3]
    for k in range(n_ticks + 1):
        s = min(k * tick * speed, limit)
        x = s / waypoint_spacing
        i = min(int(x), n - 1)
        frac = x - i
        q_ref = qs[i] + frac * (qs[i + 1] - qs[i])
        qd_ref = (
            (qs[i + 1] - qs[i]) * speed / waypoint_spacing if s < limit else np.zeros(len(joints))
        )
        force, hit = contact_force(robot, hand, obj, links)
        if force >= force_threshold:
            q_hold = arm.positions()
            travel = measured_travel()
            robot.drive(joints, q_hold)
            robot.settle(0.1)
            return PushResult(
                True, travel, Pose(start.p + travel * z, start.q), hit, force, be.time - t0
            )
        robot.hold()  # every other arm/torso joint at its last target (public API), then this arm's reference
        robot.drive(joints, q_ref, qd_ref)
        robot.step(per)  # steps the backend and lets the hands re-aim their coupled joints
    return PushResult(False, limit, cmd_poses[-1], (), 0.0, be.time - t0)
