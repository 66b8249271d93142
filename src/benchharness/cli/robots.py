"""``benchharness robots`` and ``benchharness robot inspect``: the registered robots.

Listing reads only the plugins' registrations (no torch, no simulator);
``inspect`` builds the robot and loads it on a backend created through the
plugin manager, exactly as a benchmark run would.
"""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np
from rich.table import Table

from ..plugin import get_manager
from .common import EXIT_BAD_INPUT, emit_json, fail, json_option, print_table
from .common import console as rich_console

#: The backend that renders snapshots when the chosen one cannot (PyBullet's TinyRenderer is headless).
RENDER_FALLBACK = "pybullet"


@click.command("robots")
@json_option
def robots_cmd(as_json: bool) -> None:
    """List registered robots: name, DOF, joint groups, providing distribution."""
    items = get_manager().items("robot")
    rows = [
        {
            "name": it.name,
            "dof": it.meta.get("dof"),
            "groups": list(it.meta.get("groups", [])),
            "distribution": it.distribution,
            "summary": it.summary,
        }
        for it in items
    ]
    if as_json:
        emit_json({"robots": rows})
        return
    table = Table(title="benchharness robots")
    for col in ("name", "DOF", "groups", "distribution", "summary"):
        table.add_column(col)
    for r in rows:
        table.add_row(
            r["name"],
            str(r["dof"] if r["dof"] is not None else "?"),
            ", ".join(r["groups"]),
            r["distribution"],
            r["summary"],
        )
    print_table(table)


@click.group()
def robot() -> None:
    """Inspect one robot."""


def _camera_for(points: np.ndarray):
    """A camera that frames all ``points`` (world link origins) from the front-left, slightly above."""
    from ..backends.interface import CameraSpec

    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 0.08) + 0.05
    fov = 50.0
    dist = radius / np.tan(np.radians(fov / 2)) * 1.1
    direction = np.array([1.0, 0.45, 0.5])
    direction /= np.linalg.norm(direction)
    eye = centre + direction * dist
    return CameraSpec(
        eye=tuple(eye),
        target=tuple(centre),
        width=640,
        height=480,
        fov_deg=fov,
        near=0.01,
        far=float(dist + 3 * radius),
    )


def _snapshot(robot_name: str, backend_name: str, png: Path) -> str:
    """Render the robot in its home pose to ``png``; returns the backend that rendered."""
    import matplotlib.image

    manager = get_manager()
    item = manager.get("backend", backend_name)
    renderer = backend_name if item.meta.get("capabilities", {}).get("camera") else RENDER_FALLBACK
    be = manager.create("backend", renderer)
    try:
        r = manager.create("robot", robot_name)
        r.spawn(be)
        pts = np.array([be.get_link_pose(r.body, lk).p for lk in r.link_names])
        img = be.render(_camera_for(pts))
        png.parent.mkdir(parents=True, exist_ok=True)
        matplotlib.image.imsave(str(png), np.asarray(img, dtype=np.uint8))
    finally:
        be.close()
    return renderer


@robot.command("inspect")
@click.argument("name")
@click.option(
    "--backend",
    "backend_name",
    default="pybullet",
    show_default=True,
    help="Backend to load the robot on.",
)
@click.option(
    "--png",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Save a snapshot of the robot in its home pose.",
)
@json_option
def inspect_cmd(name: str, backend_name: str, png: Path | None, as_json: bool) -> None:
    """Load robot NAME on a backend: DOF, joint limits, groups and tool frames in the home pose."""
    from ..plugin.manager import PluginNotFoundError

    manager = get_manager()
    try:
        rob = manager.create("robot", name)
        be = manager.create("backend", backend_name)
    except PluginNotFoundError as exc:
        fail(str(exc), EXIT_BAD_INPUT)
    try:
        rob.spawn(be)
        info = be.joint_info(rob.body)
        tcp = {g: be.get_link_pose(rob.body, lk) for g, lk in rob.tcp_links().items()}
        mass = be.get_mass(rob.body)
    finally:
        be.close()
    home = rob.home()
    data = {
        "name": rob.name,
        "backend": backend_name,
        "dof": rob.driven_dof,
        "mass_kg": mass,
        "urdf": str(rob.urdf_path),
        "groups": {k: list(v) for k, v in rob.groups().items()},
        "joints": [
            {
                "name": j.name,
                "type": j.type,
                "lower": j.lower,
                "upper": j.upper,
                "max_velocity": j.max_velocity,
                "max_effort": j.max_effort,
                "home": float(h),
            }
            for j, h in zip(info, home)
        ],
        "tcp_frames": {
            g: {
                "link": rob.tcp_links()[g],
                "position": p.p.tolist(),
                "quaternion_xyzw": p.q.tolist(),
            }
            for g, p in tcp.items()
        },
    }
    if png is not None:
        data["png"] = str(png)
        data["rendered_by"] = _snapshot(name, backend_name, png)
    if as_json:
        emit_json(data)
        return
    con = rich_console()
    con.print(
        f"[bold]{rob.name}[/bold] on {backend_name}: {rob.driven_dof} DOF ({rob.dof} joints), "
        f"{mass:.2f} kg, {rob.urdf_path}"
    )
    t = Table(title="joints (SI units; home = home configuration)")
    for col in ("joint", "type", "lower", "upper", "max vel", "max effort", "home"):
        t.add_column(col, justify="right" if col not in ("joint", "type") else "left")
    for j in data["joints"]:
        t.add_row(
            j["name"],
            j["type"],
            f"{j['lower']:.4f}",
            f"{j['upper']:.4f}",
            f"{j['max_velocity']:.3f}",
            f"{j['max_effort']:.1f}",
            f"{j['home']:.3f}",
        )
    print_table(t, con)
    g = Table(title="groups")
    g.add_column("group")
    g.add_column("joints")
    for k, v in data["groups"].items():
        g.add_row(k, ", ".join(v))
    print_table(g, con)
    f = Table(title="tool frames in the home pose (world; quaternion x, y, z, w)")
    for col in ("group", "link", "position (m)", "quaternion"):
        f.add_column(col)
    for k, v in data["tcp_frames"].items():
        f.add_row(
            k,
            v["link"],
            np.array2string(np.asarray(v["position"]), precision=4),
            np.array2string(np.asarray(v["quaternion_xyzw"]), precision=4),
        )
    print_table(f, con)
    if png is not None:
        note = (
            ""
            if data["rendered_by"] == backend_name
            else (
                f" (backend {backend_name!r} cannot render: snapshot rendered through {data['rendered_by']!r})"
            )
        )
        con.print(f"snapshot: {png}{note}")
