"""Issue 13 item 15: plots a person can read.

* Figure 7: a group with one sample used to be a bare black line (the box
  has zero height, so its face colour never shows). Its median and a marker
  now carry the method's colour -- checked on the drawn artists and on the
  rendered pixels.
* Pose-error plot: one 800 mm estimate flattened every other point onto
  zero. The axis now ends near the inliers; the off-scale estimate is drawn
  on the top edge and named (trial, move, value) by ``results``.
"""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner
from matplotlib.colors import to_rgba

from benchharness.metrics.plots import box_plot
from benchharness.metrics.stats import summarize_groups


def test_one_sample_group_is_drawn_in_its_method_colour(tmp_path):
    # method A: five samples on object o; method B: one sample on object o
    cols = {"object": ["o"] * 6, "method": ["A"] * 5 + ["B"]}
    values = {"err": np.array([1.0, 2.0, 3.0, 4.0, 5.0, 2.5])}
    summ = summarize_groups(cols, ["object", "method"], values, dropped=np.zeros(6, bool))
    out = tmp_path / "fig7.png"
    plot = box_plot(summ, ["err"], out)
    art = plot.artists["err"]
    b_colour = to_rgba("C1")
    assert to_rgba(art["medians"][1].get_color()) == b_colour  # B's one sample
    assert to_rgba(art["medians"][0].get_color()) == to_rgba("black")  # A's real box
    (single,) = art["singles"]
    assert tuple(single.get_facecolor()[0]) == pytest.approx(b_colour)
    assert list(single.get_offsets()[0]) == pytest.approx([0.2, 2.5])
    # and it is really there in the picture: pixels of C1 around B's position
    fig = plot.figure
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(int)
    ax = fig.axes[0]
    x, y = ax.transData.transform((0.2, 2.5))
    h = img.shape[0]
    patch = img[int(h - y) - 6 : int(h - y) + 6, int(x) - 6 : int(x) + 6]
    want = np.array(b_colour[:3]) * 255
    assert (np.abs(patch - want).sum(axis=-1) < 60).any()


PLUGIN = '''
from benchharness.cube import expected_final
from benchharness.geometry import Pose
from benchharness.plugin import Registration, hookimpl
from benchharness.runner import TrialOutcome


class WildEstimate:
    """Small pose-estimate errors, one 800 mm estimate in trial 3 at move 2."""

    def run_trial(self, ctx):
        ctx.backend.add_ground()
        ctx.recorder.contact()
        true = Pose([0.0, 0.0, 0.3])
        for i, _ in enumerate(ctx.item.sequence):
            err = 0.8 if (ctx.trial_index == 3 and i == 2) else 0.001 * (1 + i + ctx.trial_index)
            ctx.recorder.pose_estimate(i, true, Pose([err, 0.0, 0.3]))
        ctx.backend.step(10)
        return TrialOutcome(
            final_state=expected_final(ctx.item.sequence, ctx.item.initial),
            first_contact_s=ctx.sim_start,
            termination_s=ctx.sim_start + 10 * ctx.physics.timestep,
        )


@hookimpl
def benchharness_strategies():
    return [Registration("test-wild-estimate", WildEstimate, "one wild estimate")]
'''


@pytest.mark.sim
def test_pose_error_plot_keeps_a_readable_axis_and_names_the_off_scale_trial(tmp_path, monkeypatch):
    pytest.importorskip("pybullet")
    from benchharness.cli.run import results, run

    (tmp_path / "wild_plugin.py").write_text(textwrap.dedent(PLUGIN))
    monkeypatch.syspath_prepend(str(tmp_path))
    store = str(tmp_path / "s.sqlite")
    r = CliRunner().invoke(
        run,
        [
            "--task",
            "Rubiks-5-5",
            "--robot",
            "test-stub",
            "--strategy",
            "test-wild-estimate",
            "--plugin",
            "runner_testplugins",
            "--plugin",
            "wild_plugin",
            "--workers",
            "0",
            "--no-progress",
            "--store",
            store,
        ],
        catch_exceptions=False,
    )
    assert r.exit_code == 0, r.output
    png = tmp_path / "pose.png"
    r = CliRunner().invoke(results, ["--plot-pose-error", str(png), "--store", store, "--json"])
    assert r.exit_code == 0, r.output
    (o,) = [o for o in json.loads(r.stdout)["plot_off_scale"] if o["metric"] == "pos_mm"]
    assert (o["trial"], o["move"]) == (3, 2) and o["value"] == pytest.approx(800.0)
    text = CliRunner().invoke(results, ["--plot-pose-error", str(png), "--store", store]).output
    assert "off-scale" in text and "trial 3 move 2: 800 mm" in text

    # the axis: the inliers (<= 10 mm) fill the panel instead of the bottom 1 %
    import matplotlib.pyplot as plt

    from benchharness.runner.plots import plot_pose_error
    from benchharness.runner.store import ResultsStore

    captured = {}
    monkeypatch.setattr(plt, "close", lambda fig: captured.setdefault("fig", fig))
    with ResultsStore(store) as s:
        drawn = plot_pose_error(s.trials(), tmp_path / "again.png")
    top = captured["fig"].axes[0].get_ylim()[1]
    assert 10.0 < top < 20.0, top
    assert [(x.trial, x.move) for x in drawn.outliers if x.metric == "pos_mm"] == [(3, 2)]
