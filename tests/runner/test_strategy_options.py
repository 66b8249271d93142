"""``--strategy-option KEY=VALUE``: a strategy's config fields from the command line and sweep files.

Checked against the dataclasses themselves (the values a strategy is built
with), the run key (an option is a different run; the default run's key is
what it was before options existed), and the CLI's bad-input contract (exit
2, one line naming the value, nothing stored).
"""

from __future__ import annotations

import json
import sqlite3
from dataclasses import asdict

import pytest
from click.testing import CliRunner

from benchharness.cli.main import cli
from benchharness.runner.contract import TimeBudget
from benchharness.runner.options import (
    OptionError,
    apply_options,
    describe_options,
    field_docs,
    normalise_options,
)
from benchharness.runner.spec import RunSpec, stable_hash

PLUGIN = "runner_testplugins"  # tests/runner/runner_testplugins.py
BASE = ["--robot", "test-stub", "--plugin", PLUGIN, "--workers", "0", "--no-progress"]
RUN = ["run", "--task", "Rubiks-1-5", "--strategy", "test-configured", *BASE]


def _defaults():
    from runner_testplugins import ConfiguredConfig

    return {"config": ConfiguredConfig()}


def test_every_field_type_is_read_by_its_annotation():
    kwargs, canon = apply_options(
        _defaults(),
        [
            ("hold_steps", "7"),
            ("label", "fancy"),
            ("scale", "inf"),
            ("depth", "3"),
            ("offsets", "0.1, 0.2 ,0.3"),
            ("pair", "2,3"),
            ("reach.margin", "0.02"),
            ("reach.enabled", "off"),
        ],
    )
    c = kwargs["config"]
    assert (c.hold_steps, c.label, c.scale, c.depth) == (7, "fancy", float("inf"), 3)
    assert c.offsets == (0.1, 0.2, 0.3) and c.pair == (2.0, 3.0)
    assert (c.reach.margin, c.reach.enabled) == (0.02, False)
    # canonical spelling: sorted keys, values as read back
    assert dict(canon)["pair"] == "2.0,3.0" and dict(canon)["reach.enabled"] == "false"
    assert [k for k, _ in canon] == sorted(k for k, _ in canon)
    # the canonical form applies to the same configuration
    again, _ = apply_options(_defaults(), canon)
    assert again == kwargs
    # none for an optional field; the keyword itself may lead the key
    kw2, _ = apply_options(_defaults(), [("config.depth", "none")])
    assert kw2["config"].depth is None


@pytest.mark.parametrize(
    "pair, needle",
    [
        (("hold_steps", "1.5"), "hold_steps=1.5: not an integer"),
        (("scale", "nan"), "scale=nan: not a number"),
        (("scale", "fast"), "scale=fast: not a number"),
        (("reach.enabled", "maybe"), "not a yes/no value"),
        (("pair", "1,2,3"), "expected 2 comma-separated values"),
        (("reach", "1"), "'reach' is a group; set one of reach.enabled, reach.margin"),
        (("hold_step", "3"), "did you mean hold_steps?"),
        (("label", "shiny"), "label must be 'plain' or 'fancy'"),
    ],
)
def test_a_bad_key_or_value_is_named(pair, needle):
    with pytest.raises(OptionError) as err:
        apply_options(_defaults(), [pair])
    assert needle in str(err.value)


def test_options_change_the_run_key_and_the_default_key_is_unchanged():
    base = RunSpec("Rubiks-1-5", "pr2", "sensor-aided", "sapien", code="x")
    # the options hash of a run without options is the hash it had before options existed
    assert base.options_hash == stable_hash({"budget": asdict(TimeBudget()), "repeats": 1}, 12)
    a = RunSpec(**{**base.__dict__, "strategy_options": (("sweep.speed", "0.05"),)})
    assert a.run_key != base.run_key
    # "0.050" and "0.05" are one run
    from benchharness.strategies.pr2_rubiks import REGISTRATIONS

    reg = next(r for r in REGISTRATIONS if r.name == "sensor-aided")
    one = normalise_options(reg.options, reg.name, ["sweep.speed=0.050"])
    two = normalise_options(reg.options, reg.name, ["sweep.speed=5e-2"])
    assert one == two == (("sweep.speed", "0.05"),)


def test_the_builtin_strategies_are_built_with_the_options():
    from benchharness.plugin import get_manager
    from benchharness.runner.plugins import create_strategy

    spec = RunSpec(
        "Rubiks-1-5",
        "pr2",
        "sensor-aided",
        "pybullet",
        code="x",
        strategy_options=(("errors.tracking_std", "0.002"), ("pretouch_mode", "grid")),
    )
    s = create_strategy(spec)
    assert s.config.pretouch_mode == "grid" and s.config.errors.tracking_std == 0.002
    exact = get_manager().get("strategy", "dead-reckoning-exact")
    # the diagnostic's own defaults (zero error) are what its options start from
    kw, _ = apply_options(exact.options(), [("grip_force", "15")])
    assert kw["config"].errors.is_zero and kw["config"].grip_force == 15.0
    ig = get_manager().get("strategy", "point-contact")
    kw, canon = apply_options(ig.options(), [("exec_config.hold_s", "2"), ("waypoints", "8")])
    assert kw["exec_config"].hold_s == 2.0 and kw["config"].waypoints == 8
    assert canon == (("exec_config.hold_s", "2.0"), ("waypoints", "8"))
    # float | Literal["friction"] | None: each spelling reads as its own type
    for raw, value in (("30", 30.0), ("friction", "friction"), ("none", None)):
        kw, _ = apply_options(ig.options(), [("exec_config.placement_grip_cone_deg", raw)])
        assert kw["exec_config"].placement_grip_cone_deg == value
    with pytest.raises(OptionError, match="not a number / not one of friction"):
        apply_options(ig.options(), [("exec_config.placement_grip_cone_deg", "wide")])


def test_field_docs_are_the_hash_colon_comments_through_the_bases():
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig

    docs = field_docs(PR2RubiksConfig)
    assert docs["side_retreat"].startswith("a retreat whose straight way out fails")  # a base field
    assert "pretouch" in docs["pretouch_mode"].lower() or "sweep" in docs["pretouch_mode"]
    rows = {k: (t, d) for k, t, d, _ in describe_options({"config": PR2RubiksConfig()})}
    assert rows["errors.tracking_std"] == ("float", "0.001")
    assert rows["giver_depth"] == ("int | None", "none")


def _stored(path):
    with sqlite3.connect(path) as db:
        db.row_factory = sqlite3.Row
        return [dict(r) for r in db.execute("SELECT * FROM trials ORDER BY trial_index")]


def test_run_passes_the_options_to_the_strategy_and_keys_the_run(tmp_path):
    store = tmp_path / "s.sqlite"
    runner = CliRunner()
    opts = ["--strategy-option", "scale=0.50", "--strategy-option", "reach.margin=0.03"]
    r = runner.invoke(cli, [*RUN, *opts, "--store", str(store)], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    rows = _stored(store)
    assert len(rows) == 1
    events = json.loads(rows[0]["diagnostics_json"])["events"]
    config = next(e for e in events if e["kind"] == "config")
    assert config["scale"] == 0.5 and config["reach"]["margin"] == 0.03
    # the same options spelled otherwise: the same run, nothing re-run
    opts2 = ["--strategy-option", "reach.margin=3e-2", "--strategy-option", "scale=.5"]
    r = runner.invoke(cli, [*RUN, *opts2, "--store", str(store)], catch_exceptions=False)
    assert r.exit_code == 0 and "skipped 1 already stored" in r.output, r.output
    # without options: another run
    r = runner.invoke(cli, [*RUN, "--store", str(store)], catch_exceptions=False)
    assert r.exit_code == 0 and "ran 1" in r.output, r.output
    keys = {row["run_key"] for row in _stored(store)}
    assert len(keys) == 2


@pytest.mark.parametrize(
    "option, needle",
    [
        ("scale", "expected KEY=VALUE"),
        ("label=shiny", "label must be 'plain' or 'fancy'"),
        ("hold_steps=x", "hold_steps=x: not an integer"),
        ("nosuch=1", "no option 'nosuch'"),
    ],
)
def test_bad_options_are_refused_before_any_trial(tmp_path, option, needle):
    store = tmp_path / "s.sqlite"
    r = CliRunner().invoke(
        cli, [*RUN, "--strategy-option", option, "--store", str(store)], catch_exceptions=False
    )
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0], r.stderr
    assert not store.exists()


def test_a_strategy_without_options_refuses_them(tmp_path):
    store = tmp_path / "s.sqlite"
    args = ["run", "--task", "Rubiks-1-5", "--strategy", "test-drop", *BASE]
    r = CliRunner().invoke(
        cli, [*args, "--strategy-option", "a=1", "--store", str(store)], catch_exceptions=False
    )
    assert r.exit_code == 2 and "declares no options" in r.stderr
    assert not store.exists()


def test_plugins_lists_a_strategys_options_as_json():
    from benchharness.strategies.pr2_rubiks.config import PR2RubiksConfig

    r = CliRunner().invoke(cli, ["plugins", "--options", "sensor-aided", "--json"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.output)
    keys = {o["key"]: o for o in data["options"]}
    assert keys["pretouch_mode"]["default"] == PR2RubiksConfig().pretouch_mode
    assert keys["sweep.speed"] == {
        "key": "sweep.speed",
        "type": "float",
        "default": repr(PR2RubiksConfig().sweep.speed),
        "doc": keys["sweep.speed"]["doc"],
    }
    r = CliRunner().invoke(cli, ["plugins", "--options", "no-such-strategy"])
    assert r.exit_code == 2 and "no-such-strategy" in r.stderr


def test_sweep_file_options_per_strategy(tmp_path):
    from benchharness.runner.grid import expand, load_grid

    grid = tmp_path / "g.toml"
    grid.write_text(
        'tasks = ["Rubiks-1-5"]\nrobots = ["pr2"]\nstrategies = ["sensor-aided", "dead-reckoning"]\n'
        '[strategy_options.sensor-aided]\npretouch_mode = "grid"\ndetour_distances = [0.3, 0.4]\n'
    )
    specs = {s.strategy: s for s in expand(load_grid(grid)).specs}
    assert specs["sensor-aided"].strategy_options == (
        ("detour_distances", "0.3,0.4"),
        ("pretouch_mode", "grid"),
    )
    assert specs["dead-reckoning"].strategy_options == ()
    bad = tmp_path / "b.toml"
    bad.write_text(
        'tasks = ["Rubiks-1-5"]\nrobots = ["pr2"]\nstrategies = ["sensor-aided"]\n'
        "[strategy_options.sensor-aided]\nswing_routes = 3\n"
    )
    with pytest.raises(ValueError, match="strategy sensor-aided: --strategy-option swing_routes=3"):
        expand(load_grid(bad))


def test_tables_show_an_option_run_as_its_own_method_across_tiers(tmp_path):
    """Budgets differ per tier (so do options hashes): one column per option set, labelled by it."""
    from benchharness.runner.reports import _columns
    from benchharness.runner.store import ResultsStore

    store = tmp_path / "s.sqlite"
    runner = CliRunner()
    for task in ("Rubiks-1-5", "Rubiks-1-10"):
        for opts in ([], ["--strategy-option", "scale=0.5"]):
            args = ["run", "--task", task, "--strategy", "test-configured", *BASE, *opts]
            r = runner.invoke(cli, [*args, "--store", str(store)], catch_exceptions=False)
            assert r.exit_code == 0, r.output
    with ResultsStore(store, read_only=True) as s:
        trials = s.trials()
    cols, _ = _columns(trials)
    assert sorted(c.label for c in cols) == [
        "test-configured (test-stub, pybullet)",
        "test-configured [scale=0.5] (test-stub, pybullet)",
    ]
    r = runner.invoke(cli, ["table", "--benchmark", "rubiks", "--store", str(store)])
    assert r.exit_code == 0 and "[scale=0.5]" in r.output.replace("\n", ""), r.output
