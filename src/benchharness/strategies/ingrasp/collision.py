"""An optional term of the in-grasp planner: keep the hand's other parts off the object.

The relaxed-rigidity planner moves the object with the fingertips only; nothing in its cost
knows that the phalanges and the palm are solid, and in simulation some published motions carry
our object into them (the apple into the proximal phalanges). The Autonomous Robots version of
the method (Sundaralingam & Hermans 2019) adds a signed-distance cost that keeps the grasped
object off its *environment*, which a Level I task in free space does not have; this module
applies that cost's form to the hand itself: at every waypoint, for every collision shape of the
hand other than the used fingertips, the signed distance between the shape and the object's
surface, penalised below a margin. It is off by default (``IngraspConfig.w_collision``): measured
over the 100 Level I tasks it stops plans short of goals reachable only through the hand and does
not remove the drops (docs/ingrasp.md "Collision term").

Geometry (why it is cheap and differentiable): the hand's shapes are the URDF's collision boxes
and spheres, whose signed distance is closed-form; the object is a fixed sample of its surface
points (the mesh vertices, every n-th), carried by the planned object pose. The distance of a
shape to the object is the least signed distance of those points to the shape (a hard minimum:
its gradient comes from the nearest point), so the residual per (waypoint, shape) is
``sqrt(w) * relu(m - d)``, ``m`` the margin, or the shape's distance at the initial grasp where
that is smaller (the planner cannot move the initial grasp, so it must not be charged for it).
Simplifications, all parameters or stated here: the object is sampled at its vertices (a shape
can sink between two samples by up to about half their spacing), a shape wholly inside the
object is not seen (the trajectory starts outside and moves continuously), and the object pose
at a waypoint is the planned one (the set-up's noise is unknown to the planner).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import torch

from .hand import DTYPE, FINGERS, TIP_LINKS, HandKinematics, joint_indices
from .problem import InGraspProblem

__all__ = ["CollisionScene", "collision_scene", "box_signed_distance"]


def box_signed_distance(p: torch.Tensor, half: torch.Tensor) -> torch.Tensor:
    """Signed distance of points ``p`` (..., 3), in a box's frame, to the box of half extents
    ``half`` (..., 3): positive outside, negative inside (the exact Euclidean distance both ways).

    The outside part's norm carries a 1e-18 m^2 floor so that its derivative stays finite inside
    the box (a bias below 1e-9 m).
    """
    d = p.abs() - half
    outside = torch.sqrt((torch.clamp(d, min=0.0) ** 2).sum(-1) + 1e-18)
    inside = torch.clamp(d.max(dim=-1).values, max=0.0)
    return outside + inside


@dataclass(frozen=True)
class CollisionScene:
    """Everything the collision residuals need, as tensors, for one problem and object pose.

    ``points`` are the object's surface samples in the object frame the plan carries
    (``InGraspProblem.object_initial``'s frame); the shapes are grouped as those that move with
    the planned fingers (placed by the link FK) and those that stay (palm, unused fingers).
    """

    points: torch.Tensor  #: (N, 3) object surface samples in the frame the plan carries
    link_index: torch.Tensor  #: (nb,) flat (finger * 5 + link) index into ``link_poses`` rows
    box_in_link: torch.Tensor  #: (nb, 4, 4) moving boxes' centre frames in their links
    box_half: torch.Tensor  #: (nb, 3)
    static_inv: torch.Tensor  #: (ns, 4, 4) palm <- box inverses of the boxes that stay
    static_half: torch.Tensor  #: (ns, 3)
    sphere_centres: torch.Tensor  #: (nc, 3) spheres that stay (unused fingertips), palm frame
    sphere_radii: torch.Tensor  #: (nc,)
    names: tuple[str, ...]  #: one per residual column: moving boxes, static boxes, spheres
    fingers: tuple[str, ...]  #: the planned fingers, in the plan's joint order
    #: (4 k,) rad, commanded minus touching joints at the initial grasp: the plan's rows are the
    #: fingers' set-points, and a PD finger squeezing the object stands that far short of them
    joint_offset: torch.Tensor
    margin: float = 0.001
    #: (nb + ns + nc,) per shape: the margin, or the distance at the initial grasp where smaller
    allowed: torch.Tensor | None = None

    def hand_links(self, hand: HandKinematics, q: torch.Tensor) -> torch.Tensor:
        """Where the planned fingers' links are (T, k, 5, 4, 4) for plan rows ``q`` (T, 4 k): the
        set-points less the squeeze (:attr:`joint_offset`)."""
        return hand.link_poses(q - self.joint_offset, self.fingers)

    def distances(
        self, links: torch.Tensor, object_poses: torch.Tensor, active: torch.Tensor | None = None
    ) -> torch.Tensor:
        """Signed distance (m) of every shape to the object at every waypoint -> (T, shapes).

        ``links``: (T, k, 5, 4, 4) from :meth:`hand_links`; ``object_poses``:
        (T, 4, 4) planned object frames in the palm frame. ``active`` (T, shapes): per waypoint and
        shape, the one surface sample to measure (:meth:`nearest`); without it every sample is
        measured and the least distance taken. Both give the same value and derivative where
        ``active`` holds the nearest samples (the minimum's derivative is its argument's); the
        solver's Jacobian taken through every sample costs ~100x more (measured: minutes a plan).
        """
        return self._sample_distances(links, object_poses, active).amin(-1)

    def nearest(self, links: torch.Tensor, object_poses: torch.Tensor) -> torch.Tensor:
        """Per waypoint and shape, the index of the nearest surface sample (least signed distance)
        -> (T, shapes), without derivatives: the active set for :meth:`distances`."""
        with torch.no_grad():
            return self._sample_distances(links, object_poses, None).argmin(-1)

    def _sample_distances(
        self, links: torch.Tensor, object_poses: torch.Tensor, active: torch.Tensor | None
    ) -> torch.Tensor:
        """(T, shapes, M): signed distances of M samples per shape (all N, or the ``active`` one)."""
        n_t = object_poses.shape[0]
        rot_t = object_poses[:, :3, :3].transpose(-1, -2)
        if active is None:  # (T, 1, N, 3): every sample, shared by the shapes
            pts = (self.points @ rot_t)[:, None]
        else:  # (T, S, 1, 3): one sample per shape
            pts = self.points[active][..., None, :] @ rot_t[:, None]
        pts = pts + object_poses[:, None, None, :3, 3]
        nb, ns = self.box_in_link.shape[0], self.static_inv.shape[0]

        def cols(c: slice) -> torch.Tensor:
            return pts if active is None else pts[:, c]

        parts = []
        if nb:
            box = links.reshape(n_t, -1, 4, 4)[:, self.link_index] @ self.box_in_link[None]
            local = (cols(slice(0, nb)) - box[:, :, None, :3, 3]) @ box[..., :3, :3]
            parts.append(box_signed_distance(local, self.box_half[None, :, None]))
        if ns:
            inv = self.static_inv[None]
            local = cols(slice(nb, nb + ns)) @ inv[..., :3, :3].transpose(-1, -2)
            local = local + inv[:, :, None, :3, 3]
            parts.append(box_signed_distance(local, self.static_half[None, :, None]))
        if self.sphere_centres.shape[0]:
            gap = (cols(slice(nb + ns, None)) - self.sphere_centres[None, :, None]).norm(dim=-1)
            parts.append(gap - self.sphere_radii[None, :, None])
        return torch.cat(parts, dim=1)

    def residuals(
        self,
        links: torch.Tensor,
        object_poses: torch.Tensor,
        weight: float,
        active: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """``sqrt(weight) * relu(allowed - distance)`` per waypoint and shape, flattened."""
        d = self.distances(links, object_poses, active)
        allowed = self.allowed if self.allowed is not None else torch.full_like(d[0], self.margin)
        return (weight**0.5) * torch.relu(allowed[None] - d).reshape(-1)


def collision_scene(
    hand: HandKinematics,
    problem: InGraspProblem,
    surface_points: np.ndarray,
    body_in_palm: np.ndarray,
    *,
    q_touch: np.ndarray | None = None,
    margin: float = 0.001,
    max_points: int = 600,
) -> CollisionScene:
    """The collision scene of ``problem``: the hand at its initial grasp with the object's surface
    ``surface_points`` (object body frame, metres) at ``body_in_palm`` (4x4: where the set-up puts
    the body in the palm frame at the initial grasp). ``q_touch`` (16,): where the hand stands
    there (the set-up's touching joints, ``ExecConfig.grasp_q0``); default the published ``q_0``.

    Every URDF collision shape takes part except the used fingertips' spheres (they are the
    contacts). ``max_points``: surface samples kept (every n-th vertex, a fixed stride: no
    randomness). The allowed distance of each shape is ``margin`` or its distance at the initial
    grasp, whichever is smaller.
    """
    from .placement import hand_geometry, link_frames

    geo = hand_geometry(hand.urdf_path)
    q_at = np.asarray(problem.q_rest if q_touch is None else q_touch, float)
    frames = link_frames(hand, q_at)
    offset = problem.q0 - q_at[joint_indices(problem.fingers)]
    used_links = {
        name: 5 * i + j
        for i, f in enumerate(problem.fingers)
        for j, name in enumerate(_finger_links(f))
    }
    t = lambda a: torch.as_tensor(np.asarray(a, float), dtype=DTYPE)  # noqa: E731
    idx, in_link, half, names = [], [], [], []
    s_inv, s_half, s_names = [], [], []
    for link, lst in sorted(geo.boxes.items()):
        for origin, h in lst:
            if link in used_links:
                idx.append(used_links[link])
                in_link.append(origin)
                half.append(h)
                names.append(link)
            elif link in frames:
                s_inv.append(np.linalg.inv(frames[link] @ origin))
                s_half.append(h)
                s_names.append(link)
    c_pos, c_rad, c_names = [], [], []
    for link, balls in sorted(geo.spheres.items()):
        if link in used_links or link not in frames:  # the used fingertips are the contacts
            continue
        for c, r in balls:
            c_pos.append((frames[link] @ np.append(c, 1.0))[:3])
            c_rad.append(r)
            c_names.append(link)
    pts = np.asarray(surface_points, float)
    pts = pts[:: max(1, len(pts) // max(1, max_points))]
    # the samples in the frame the plan carries (the task's object frame): at the initial grasp
    # that frame is ``problem.object_initial``, and the body sits at ``body_in_palm``
    to_task = np.linalg.inv(problem.object_initial) @ np.asarray(body_in_palm, float)
    pts = pts @ to_task[:3, :3].T + to_task[:3, 3]
    scene = CollisionScene(
        points=t(pts),
        link_index=torch.as_tensor(idx, dtype=torch.long),
        box_in_link=t(np.array(in_link).reshape(-1, 4, 4)),
        box_half=t(np.array(half).reshape(-1, 3)),
        static_inv=t(np.array(s_inv).reshape(-1, 4, 4)),
        static_half=t(np.array(s_half).reshape(-1, 3)),
        sphere_centres=t(np.array(c_pos).reshape(-1, 3)),
        sphere_radii=t(np.array(c_rad).reshape(-1)),
        names=tuple(names + s_names + c_names),
        fingers=problem.fingers,
        joint_offset=t(offset),
        margin=margin,
    )
    with torch.no_grad():
        links = scene.hand_links(hand, t(problem.q0)[None])
        d0 = scene.distances(links, t(problem.object_initial)[None])[0]
    return replace(scene, allowed=torch.clamp(d0, max=margin))


def _finger_links(finger: str) -> tuple[str, ...]:
    """The link names of ``finger`` in chain order (four phalanx links, then the tip)."""
    base = 4 * FINGERS.index(finger)
    return (*(f"link_{base + j}" for j in range(4)), TIP_LINKS[finger])
