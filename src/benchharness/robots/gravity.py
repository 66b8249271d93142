"""Gravity torques of a robot from its URDF masses, for feed-forward compensation.

Why: the Backend interface drives joints with a PD law only. A PD arm under
gravity sags by ``tau_g / k``; for a PR2 arm held out horizontally the
shoulder needs ~48 N m, more than its 30 N m motor — the real robot carries
its arms on spring counterbalances. Feeding ``tau_g`` forward as a shifted
position target (``q* + tau_g / k``) removes the sag on every backend
without changing the interface.

Holding torque of joint j: ``tau_j = -sum_i m_i g . dc_i/dq_j`` over links i
downstream of j (revolute: ``a_j x (c_i - o_j)``; prismatic: ``a_j``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .description import downstream_links
from .kinematics import KinematicTree

__all__ = ["GravityModel"]


class GravityModel:
    def __init__(self, urdf: str | Path, gravity: Sequence[float] = (0.0, 0.0, -9.81)) -> None:
        text = Path(urdf).read_text()
        root = ET.fromstring(text)
        self.tree = KinematicTree(text)
        self.gravity = np.asarray(gravity, dtype=float)
        self.mass: dict[str, float] = {}
        self.com: dict[str, np.ndarray] = {}
        for link in root.findall("link"):
            inertial = link.find("inertial")
            if inertial is None:
                continue
            m = inertial.find("mass")
            o = inertial.find("origin")
            self.mass[link.get("name")] = float(m.get("value")) if m is not None else 0.0
            self.com[link.get("name")] = np.array(
                [float(x) for x in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
            )
        self.joints: dict[str, tuple[str, str, np.ndarray]] = {}  # name -> (type, child, axis)
        for j in root.findall("joint"):
            child = j.find("child").get("link")
            ax = j.find("axis")
            axis = np.array(
                [float(x) for x in (ax.get("xyz") if ax is not None else "1 0 0").split()]
            )
            self.joints[j.get("name")] = (j.get("type"), child, axis / np.linalg.norm(axis))
        self.downstream: dict[str, list[str]] = {
            name: [lk for lk in links if self.mass.get(lk, 0.0) > 0]
            for name, links in downstream_links(root).items()
        }
        # Vectorised form: Q_j = a_j . ((S_j - M_j o_j) x g) with S_j = sum m_i c_i and M_j = sum m_i
        # over the links downstream of joint j (prismatic: Q_j = M_j g . a_j).
        self._links = [lk for lk in self.mass if self.mass[lk] > 0]
        self._m = np.array([self.mass[lk] for lk in self._links])
        self._com_local = np.array([self.com[lk] for lk in self._links])
        self._row: dict[str, np.ndarray] = {}
        index = {lk: k for k, lk in enumerate(self._links)}
        for name, links in self.downstream.items():
            w = np.zeros(len(self._links))
            w[[index[lk] for lk in links]] = 1.0
            self._row[name] = w

    def torques(
        self, q: Mapping[str, float], joints: Sequence[str], base_rotation: np.ndarray | None = None
    ) -> np.ndarray:
        """Holding torques (N m or N) of ``joints`` at configuration ``q``.

        ``base_rotation`` is the world rotation of the URDF root (gravity is
        given in the world frame).
        """
        g = self.gravity if base_rotation is None else np.asarray(base_rotation).T @ self.gravity
        tf = self.tree.fk(q)
        rot = np.stack([tf[lk][:3, :3] for lk in self._links])
        pos = np.stack([tf[lk][:3, 3] for lk in self._links])
        com = np.einsum("kij,kj->ki", rot, self._com_local) + pos
        mc = self._m[:, None] * com
        w = np.stack([self._row[j] for j in joints])  # (J, L)
        mass = w @ self._m  # (J,)
        s = w @ mc  # (J, 3)
        child_tf = [tf[self.joints[j][1]] for j in joints]
        a = np.stack([t[:3, :3] @ self.joints[j][2] for t, j in zip(child_tf, joints)])
        o = np.stack([t[:3, 3] for t in child_tf])
        moment = np.cross(s - mass[:, None] * o, g)
        gen = np.einsum("ji,ji->j", a, moment)
        prismatic = np.array([self.joints[j][0] == "prismatic" for j in joints])
        gen[prismatic] = mass[prismatic] * (a[prismatic] @ g)
        return -gen
