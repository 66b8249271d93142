"""Run ``benchharness`` with a torsional contact patch on the Allegro's fingertips in SAPIEN (an experiment).

PhysX gives a sphere's point contact no torsional friction; PyBullet gives every contact an arm of
``PhysicsConfig.torsional_friction`` (10 mm) times the pair's friction. This script sets the
``patch_radius`` and ``min_patch_radius`` of every ``*_tip`` shape of a robot spawned in SAPIEN to
``RADIUS`` metres, to measure how much of the engines' difference in in-hand drops that is
(docs/ingrasp.md, "What still separates the engines"). It wraps ``Robot.spawn`` in this process only
(give ``--workers 0``); nothing of the package changes. Example::

    python bench/fingertip_torsion.py 0.0015 run --task inhand-level1 --robot allegro \\
        --strategy relaxed-rigidity --backend sapien --workers 0 --store patch.sqlite
"""

from __future__ import annotations

import sys

from benchharness.robots.robot import Robot


def main() -> None:
    radius = float(sys.argv[1])
    spawn = Robot.spawn

    def spawn_with_patch(self, backend, *args, **kwargs):
        out = spawn(self, backend, *args, **kwargs)
        if type(backend).__name__ == "SapienBackend":
            body = backend._b(self.body)
            for link in body.articulation.get_links():
                if link.get_name().endswith("_tip"):
                    for shape in link.get_collision_shapes():
                        shape.set_patch_radius(radius)
                        shape.set_min_patch_radius(radius)
        return out

    Robot.spawn = spawn_with_patch  # type: ignore[method-assign]
    from benchharness.cli.main import cli

    cli(sys.argv[2:])


if __name__ == "__main__":
    main()
