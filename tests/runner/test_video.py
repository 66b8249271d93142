"""Trial videos: the overlay, the frame schedule, determinism, and results unchanged by filming."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from benchharness.cli.run import run
from benchharness.cube import parse_sequence
from benchharness.runner.recorder import TrialRecorder
from benchharness.runner.video import (
    VIDEO_SIZE,
    VideoSpec,
    _Overlay,
    burn_in,
    camera_for,
    rubiks_camera,
)

pytestmark = pytest.mark.sim

PLUGIN = "runner_testplugins"  # tests/runner/runner_testplugins.py
BASE = ["--robot", "test-stub", "--plugin", PLUGIN, "--workers", "0", "--no-progress"]


def _json(result):
    return json.loads(result.output[result.output.index("{") :])


def test_burn_in_draws_a_readable_box_and_nothing_else():
    frame = np.full((480, 640, 3), 180, dtype=np.uint8)
    out = burn_in(frame, ["Rubiks-1-5 trial 1", "move 3/5: F' (twist)", "t = 12.34 s"])
    assert out.shape == frame.shape and out.dtype == np.uint8
    changed = np.any(out != frame, axis=2)
    ys, xs = np.nonzero(changed)
    # only a box in the top-left corner changes: dark background, white text inside it
    assert ys.max() < 480 // 4 and xs.max() < 640 // 2
    box = out[: ys.max() + 1, : xs.max() + 1]
    assert np.mean(box < 40) > 0.6 and np.any(box > 200)
    assert np.array_equal(out[ys.max() + 2 :], frame[ys.max() + 2 :])
    assert burn_in(frame, []) is frame


def _ctx(sequence: str):
    t = [0.0]
    rec = TrialRecorder(clock=lambda: t[0])
    item = SimpleNamespace(tier="Rubiks-1-5", trial=1, sequence=parse_sequence(sequence))
    backend = SimpleNamespace(time=0.0)
    return SimpleNamespace(item=item, recorder=rec, backend=backend, sim_start=0.0), t


def test_overlay_follows_the_moves_and_the_clock():
    ctx, t = _ctx("R U F' D2 L")
    ov = _Overlay(ctx)
    assert ov.lines() == ["Rubiks-1-5 trial 1", "move 1/5: R", "t = 0.00 s"]
    ctx.recorder.event("action", action="Pick")
    t[0] = ctx.backend.time = 1.5
    ctx.recorder.contact()
    ctx.recorder.event("action", action="Twist")
    ctx.recorder.move(0, "R")
    ctx.recorder.move(1, "U")
    ctx.recorder.event("action", action="Twist")
    ctx.backend.time = 3.25
    lines = ov.lines()
    assert lines[1] == "move 3/5: F' (twist)"
    assert lines[2] == "t = 3.25 s, since contact 1.75 s"
    for i, m in enumerate(["F'", "D2", "L"], start=2):
        ctx.recorder.move(i, m)
    ctx.recorder.event("action", action="Release")
    assert ov.lines()[1] == "5/5 moves done (release)"


def test_views():
    close, wide = rubiks_camera((0.6, 0, 0.58), "close"), rubiks_camera((0.6, 0, 0.58), "wide")
    assert (close.width, close.height) == VIDEO_SIZE == (400, 300)
    d_close = np.linalg.norm(np.subtract(close.eye, close.target))
    d_wide = np.linalg.norm(np.subtract(wide.eye, wide.target))
    # the 5.7 cm cube at the target spans more than a fifth of the close view's height
    span = 2 * d_close * math.tan(math.radians(close.fov_deg) / 2)
    assert 0.057 / span > 0.2 and d_wide > 3 * d_close
    strategy = SimpleNamespace(video_camera=lambda view, size: rubiks_camera((1, 0, 1), view, size))
    spec = VideoSpec("v.mp4", view="wide", size=(320, 240))
    cam = camera_for(spec, strategy, None)
    assert cam.target[0] == 1 and (cam.width, cam.height) == (320, 240)
    with pytest.raises(ValueError):
        VideoSpec("v.mp4", view="sideways")


def _frames(path):
    import imageio_ffmpeg

    gen = imageio_ffmpeg.read_frames(str(path))
    meta = next(gen)
    w, h = meta["size"]
    return [np.frombuffer(f, dtype=np.uint8).reshape(h, w, 3) for f in gen]


def test_filming_changes_no_result_and_is_deterministic(invoke, tmp_path):
    """Same trial three times: without video, and filmed twice; same record, same frames."""
    pytest.importorskip("imageio_ffmpeg")
    args = ["--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE, "--json"]
    plain = _json(invoke(run, *args, store=tmp_path / "a.sqlite"))["trials"][0]
    filmed = []
    for k in range(2):
        mp4 = tmp_path / f"v{k}.mp4"
        r = invoke(
            run,
            *args,
            "--video",
            str(mp4),
            "--video-size",
            "160x120",
            store=tmp_path / f"v{k}.sqlite",
        )
        assert r.exit_code == 0, r.output
        filmed.append((_json(r)["trials"][0], _frames(mp4)))
    for rec, _ in filmed:
        for key in ("status", "score", "failure_cause", "sim_s", "first_contact_s"):
            assert rec[key] == plain[key], key
    (_, a), (_, b) = filmed
    assert len(a) == len(b) >= 2 and all(np.array_equal(x, y) for x, y in zip(a, b))
    assert a[0].shape == (120, 160, 3)
    assert not np.array_equal(a[0], a[-1])  # the clock runs (and the box falls)


def test_only_the_filmed_trial_builds_drawn_geometry(invoke, tmp_path):
    """Backend.set_visuals: colours and render-only shapes for the filmed trial, none for the rest."""
    pytest.importorskip("imageio_ffmpeg")
    args = ["--task", "Rubiks-5-5", "--strategy", "test-configured", *BASE, "--json"]
    r = invoke(
        run,
        *args,
        "--video",
        str(tmp_path / "t.mp4"),
        "--video-trial",
        "2",
        "--video-size",
        "160x120",
        store=tmp_path / "a.sqlite",
    )
    assert r.exit_code == 0, r.output
    import sqlite3

    with sqlite3.connect(tmp_path / "a.sqlite") as db:
        rows = db.execute("SELECT trial_index, diagnostics_json FROM trials").fetchall()
    drawn = {
        i: next(e for e in json.loads(d)["events"] if e["kind"] == "backend")["draws_visuals"]
        for i, d in rows
    }
    assert drawn == {1: False, 2: True, 3: False, 4: False, 5: False}


@pytest.mark.slow
def test_a_pr2_trial_scores_the_same_filmed(invoke, tmp_path):
    """Rubiks-1-5, PR2, exact dead reckoning: the stored score and status do not depend on --video."""
    args = [
        "--task",
        "Rubiks-1-5",
        "--robot",
        "pr2",
        "--strategy",
        "dead-reckoning-exact",
        "--workers",
        "0",
        "--no-progress",
        "--json",
    ]
    plain = _json(invoke(run, *args, store=tmp_path / "a.sqlite"))["trials"][0]
    r = invoke(run, *args, "--video", str(tmp_path / "t.mp4"), store=tmp_path / "b.sqlite")
    filmed = _json(r)["trials"][0]
    for key in ("status", "score", "failure_cause", "sim_s", "first_contact_s"):
        assert filmed[key] == plain[key], key
