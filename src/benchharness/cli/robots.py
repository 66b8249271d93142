"""``benchharness robots`` and ``benchharness robot inspect``: the registered robots.

Listing reads only the plugins' registrations (no torch, no simulator);
``inspect`` builds the robot and loads it on a backend created through the
plugin manager, exactly as a benchmark run would.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np
from rich.table import Table

from ..plugin import get_manager
from .common import EXIT_BAD_INPUT, emit_json, fail, json_option, print_table
from .common import console as rich_console

#: Default size of ``robot inspect --png`` (pixels, width x height): two square-ish panels.
PNG_SIZE = (1400, 700)
_MIN_PNG, _MAX_PNG = 300, 8000


def _parse_size(ctx: click.Context, param: click.Parameter, value: str) -> tuple[int, int]:
    """``WxH`` in pixels, each within [300, 8000]."""
    parts = value.lower().split("x")
    try:
        w, h = (int(p) for p in parts) if len(parts) == 2 else (0, 0)
    except ValueError:
        w, h = 0, 0
    if not (_MIN_PNG <= w <= _MAX_PNG and _MIN_PNG <= h <= _MAX_PNG):
        raise click.BadParameter(
            f"{value!r} is not WIDTHxHEIGHT in pixels, each {_MIN_PNG}..{_MAX_PNG} (e.g. 1400x700)"
        )
    return w, h


def _parse_joints(text: str, rob: Any) -> dict[str, float]:
    """``name=value,...`` (radians or metres) -> values, checked against ``rob``'s joints and
    hard limits; a bad item exits 2 naming it."""
    out: dict[str, float] = {}
    for item in (t.strip() for t in text.split(",")):
        if not item:
            continue
        name, sep, val = item.partition("=")
        name = name.strip()
        if not sep:
            fail(f"--joints {item!r}: expected name=value")
        if name not in rob.urdf_joints:
            fail(
                f"--joints {item!r}: robot {rob.name!r} has no movable joint {name!r} "
                f"(its joints: {', '.join(rob.joint_names)})"
            )
        try:
            x = float(val)
        except ValueError:
            fail(f"--joints {item!r}: {val.strip()!r} is not a number")
        j = rob.urdf_joints[name]
        if not np.isfinite(x) or not (j.lower - 1e-9 <= x <= j.upper + 1e-9):
            fail(f"--joints {item!r}: outside joint {name!r}'s limits [{j.lower:g}, {j.upper:g}]")
        out[name] = x
    return out


@click.command("robots")
@json_option
def robots_cmd(as_json: bool) -> None:
    """List registered robots: name, DOF, joint groups, providing distribution."""
    items = get_manager().items("robot")
    rows: list[dict[str, Any]] = [
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
    help="Draw the robot's geometry (side and top view, one colour per link) into this PNG; "
    "its folder must exist.",
)
@click.option(
    "--size",
    default=f"{PNG_SIZE[0]}x{PNG_SIZE[1]}",
    show_default=True,
    callback=_parse_size,
    help="Size of the --png image in pixels, WIDTHxHEIGHT.",
)
@click.option(
    "--frames", is_flag=True, help="--png: draw an RGB (x, y, z) triad at every movable joint."
)
@click.option("--frame-labels", is_flag=True, help="--png: label the triads with joint names.")
@click.option(
    "--joints",
    "joints_text",
    default=None,
    metavar="NAME=VALUE,...",
    help="--png: draw at these joint values (rad or m; the others stay at home).",
)
@json_option
def inspect_cmd(
    name: str,
    backend_name: str,
    png: Path | None,
    size: tuple[int, int],
    frames: bool,
    frame_labels: bool,
    joints_text: str | None,
    as_json: bool,
) -> None:
    """Load robot NAME on a backend: DOF, joint limits, groups and tool frames in the home pose.

    --png draws the robot without a simulator camera (headless, deterministic):
    its URDF collision shapes, posed by our FK at the home configuration (or
    --joints), in a side view (from -y) and a top view (from +z) with the
    floor and metre axes; --frames adds joint frames.
    """
    from ..plugin.manager import PluginNotFoundError

    if png is not None and not png.parent.is_dir():
        fail(f"--png {png}: folder {png.parent} does not exist")
    if png is None and (frames or frame_labels or joints_text):
        fail("--frames, --frame-labels and --joints only apply with --png")
    manager = get_manager()
    try:
        rob = manager.create("robot", name)
    except PluginNotFoundError as exc:
        fail(str(exc), EXIT_BAD_INPUT)
    q_draw = _parse_joints(joints_text, rob) if joints_text else {}
    try:
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
        from ..robots.sketch import draw_robot

        drawn = draw_robot(rob, png, q=q_draw, size=size, frames=frames, frame_labels=frame_labels)
        data["png"] = str(png)
        data["drawing"] = {**drawn.as_dict(), "joints": q_draw}
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
        at = ", ".join(f"{k}={v:g}" for k, v in q_draw.items())
        con.print(
            f"drawing: {png} ({size[0]}x{size[1]} px; side and top view; "
            + (f"home pose but {at}" if at else "home pose")
            + (", joint frames" if frames else "")
            + ")"
        )
