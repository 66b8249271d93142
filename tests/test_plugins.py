"""The plugin manager: discovery through entry points, fault isolation, clear errors.

Third-party distributions are simulated with real ``.dist-info`` folders on
``sys.path``, which is exactly what ``importlib.metadata`` reads for an
installed package.
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from benchharness.plugin import (
    PluginManager,
    PluginNotFoundError,
    Registration,
    get_manager,
    hookimpl,
)


def make_distribution(
    root: Path, dist: str, entry_points: dict[str, str], modules: dict[str, str]
) -> None:
    """Write an installed-looking distribution (dist-info + modules) under ``root``."""
    info = root / f"{dist.replace('-', '_')}-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 0.1\n")
    eps = "\n".join(f"{k} = {v}" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[benchharness]\n{eps}\n")
    for name, src in modules.items():
        (root / f"{name}.py").write_text(textwrap.dedent(src))


@pytest.fixture
def site(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    for mod in [m for m in sys.modules if m.startswith("thirdparty_")]:
        del sys.modules[mod]


GOOD = """
from benchharness.plugin import Registration, hookimpl

@hookimpl
def benchharness_robots():
    return [Registration("thirdparty-arm", lambda **kw: ("arm", kw), "A third-party arm")]

@hookimpl
def benchharness_strategies():
    return [Registration("thirdparty-wiggle", lambda **kw: "wiggle", "Wiggles")]
"""


def test_builtins_come_through_entry_points():
    m = get_manager(reload=True)
    tasks = m.items("task")
    assert tasks, "built-in tasks must be registered"
    assert {it.distribution for it in tasks} == {"benchharness"}
    assert all(it.entry_point.startswith(("rubiks_tasks", "inhand_tasks")) for it in tasks)
    assert not m.errors, m.errors


def test_third_party_items_appear_with_their_distribution(site):
    make_distribution(
        site, "thirdparty-good", {"good": "thirdparty_good"}, {"thirdparty_good": GOOD}
    )
    m = PluginManager()
    m.load_entry_points()
    arm = m.get("robot", "thirdparty-arm")
    assert arm.distribution == "thirdparty-good"
    assert arm.entry_point == "good = thirdparty_good"
    assert arm.create(x=1) == ("arm", {"x": 1})
    assert m.get("strategy", "thirdparty-wiggle").summary == "Wiggles"


def test_import_failure_is_isolated_and_named(site):
    make_distribution(
        site, "thirdparty-good", {"good": "thirdparty_good"}, {"thirdparty_good": GOOD}
    )
    make_distribution(
        site,
        "thirdparty-broken",
        {"broken": "thirdparty_broken"},
        {"thirdparty_broken": "import does_not_exist_anywhere\n"},
    )
    m = PluginManager()
    m.load_entry_points()
    assert m.get("robot", "thirdparty-arm")  # the good plugin still loaded
    (err,) = [e for e in m.errors if e.distribution == "thirdparty-broken"]
    assert err.entry_point == "broken = thirdparty_broken"
    assert "does_not_exist_anywhere" in err.reason
    text = str(err)
    assert "thirdparty-broken" in text and "broken = thirdparty_broken" in text


def test_missing_module_in_entry_point(site):
    make_distribution(site, "thirdparty-typo", {"typo": "thirdparty_nosuchmodule"}, {})
    m = PluginManager()
    m.load_entry_points()
    (err,) = [e for e in m.errors if e.distribution == "thirdparty-typo"]
    assert "thirdparty_nosuchmodule" in err.reason


def test_duplicate_name_keeps_first_and_reports_both(site):
    dup = GOOD.replace("A third-party arm", "An impostor")
    make_distribution(site, "thirdparty-aaa", {"a": "thirdparty_aaa"}, {"thirdparty_aaa": GOOD})
    make_distribution(site, "thirdparty-zzz", {"z": "thirdparty_zzz"}, {"thirdparty_zzz": dup})
    m = PluginManager()
    m.load_entry_points()
    assert m.get("robot", "thirdparty-arm").distribution == "thirdparty-aaa"
    (err,) = [e for e in m.errors if "duplicate" in e.reason and "thirdparty-arm" in e.reason]
    assert err.distribution == "thirdparty-zzz"
    assert "thirdparty-aaa" in err.reason  # names the first registrant too


def test_builtin_names_cannot_be_shadowed(site):
    name = get_manager(reload=True).items("task")[0].name
    src = f"""
from benchharness.plugin import Registration, hookimpl
@hookimpl
def benchharness_tasks():
    return [Registration({name!r}, lambda: "impostor")]
"""
    make_distribution(
        site, "aaa-shadow", {"shadow": "thirdparty_shadow"}, {"thirdparty_shadow": src}
    )
    m = PluginManager()
    m.load_entry_points()
    assert m.get("task", name).distribution == "benchharness"
    assert any(e.distribution == "aaa-shadow" and "duplicate" in e.reason for e in m.errors)


def test_raising_hook_is_isolated():
    class Bad:
        @hookimpl
        def benchharness_robots(self):
            raise RuntimeError("boom")

        @hookimpl
        def benchharness_tasks(self):
            return [Registration("still-here", lambda: 1)]

    m = PluginManager()
    m.register_module(Bad(), entry_point="bad = bad", distribution="bad-dist")
    assert m.get("task", "still-here").create() == 1
    (err,) = m.errors
    assert "benchharness_robots" in err.reason and "boom" in err.reason


def test_wrong_return_type_is_reported():
    class Wrong:
        @hookimpl
        def benchharness_sensors(self):
            return ["not a registration"]

    m = PluginManager()
    m.register_module(Wrong(), entry_point="w = w", distribution="w-dist")
    assert m.items("sensor") == []
    assert "not Registration" in m.errors[0].reason


def test_not_found_error_lists_available_and_failures(site):
    make_distribution(
        site,
        "thirdparty-broken",
        {"broken": "thirdparty_broken"},
        {"thirdparty_broken": "raise ImportError('needs libfoo')\n"},
    )
    m = PluginManager()
    m.load_entry_points()
    with pytest.raises(PluginNotFoundError) as info:
        m.get("robot", "nonexistent-bot")
    msg = str(info.value)
    assert "nonexistent-bot" in msg
    assert "'benchharness' entry-point group" in msg
    assert "thirdparty-broken" in msg and "needs libfoo" in msg


def test_unknown_kind_is_rejected():
    with pytest.raises(ValueError, match="unknown kind"):
        PluginManager().items("gizmo")


def test_inhand_task_sets_load_the_published_tasks():
    m = get_manager(reload=True)
    level1 = m.create("task", "inhand-level1")
    assert (
        level1.level == 1
    ).sum() == 100  # 10 objects x 2 initial x 5 desired grasps (paper IV-A1)
    assert len(set(level1.object[level1.level == 1])) == 10
    dmg = m.create("task", "inhand-level3-dmg")
    assert sorted(dmg.object) == ["cracker box", "gelatin box", "potted meat can", "spatula"]


# -- hooks go through pluggy's relay; hook names are checked ------------------------------------

TYPO = """
from benchharness.plugin import Registration, hookimpl

@hookimpl
def benchharness_robot():  # the hook is benchharness_robots
    return [Registration("typo-arm", lambda **kw: "arm")]

@hookimpl
def benchharness_tasks():
    return [Registration("typo-task", lambda **kw: "task")]
"""

UNMARKED = """
from benchharness.plugin import Registration

def benchharness_robots():  # no @hookimpl: pluggy never calls it
    return [Registration("unmarked-arm", lambda **kw: "arm")]
"""


def test_misspelled_hook_is_a_load_error_naming_entry_point_and_distribution(site):
    make_distribution(
        site, "thirdparty-good", {"good": "thirdparty_good"}, {"thirdparty_good": GOOD}
    )
    make_distribution(
        site, "thirdparty-typo", {"typo": "thirdparty_typo"}, {"thirdparty_typo": TYPO}
    )
    m = PluginManager()
    m.load_entry_points()
    assert m.get("robot", "thirdparty-arm")  # every other plugin still loads
    (err,) = [e for e in m.errors if e.distribution == "thirdparty-typo"]
    assert err.entry_point == "typo = thirdparty_typo"
    assert "unknown hook 'benchharness_robot'" in err.reason
    assert "benchharness_robots" in err.reason  # the hooks that exist are listed
    # refused whole: its correctly spelled hook would hide the typo
    assert "typo-task" not in m.names("task") and "typo-arm" not in m.names("robot")
    assert "thirdparty_typo" not in {
        m.pluggy_manager.get_name(p) for p in m.pluggy_manager.get_plugins()
    }


def test_unmarked_hook_is_a_load_error_not_called(site):
    make_distribution(
        site,
        "thirdparty-unmarked",
        {"unm": "thirdparty_unmarked"},
        {"thirdparty_unmarked": UNMARKED},
    )
    m = PluginManager()
    m.load_entry_points()
    assert "unmarked-arm" not in m.names("robot")
    (err,) = [e for e in m.errors if e.distribution == "thirdparty-unmarked"]
    assert "benchharness_robots is not marked with @hookimpl" in err.reason
    assert "unm = thirdparty_unmarked" in str(err) and "thirdparty-unmarked" in str(err)


def test_hooks_are_called_through_the_relay(site):
    """Items come from pluggy's hook relay: what ``pm.hook`` returns is what is registered."""
    make_distribution(
        site, "thirdparty-good", {"good": "thirdparty_good"}, {"thirdparty_good": GOOD}
    )
    m = PluginManager()
    m.load_entry_points()
    relay = m.pluggy_manager.hook
    from_relay = {r.name for regs in relay.benchharness_robots() for r in regs}
    assert from_relay == set(m.names("robot"))
    assert {"pr2", "thirdparty-arm"} <= from_relay
    # each implementation pluggy knows is named by its entry point (provenance)
    impl_names = {i.plugin_name for i in relay.benchharness_robots.get_hookimpls()}
    assert "good = thirdparty_good" in impl_names
    assert "robots = benchharness_builtins.robots" in impl_names


def test_every_builtin_module_is_a_clean_pluggy_plugin():
    """The built-ins are registered in one style: entry point, @hookimpl hooks, no errors."""
    m = get_manager(reload=True)
    assert not m.errors, m.errors
    names = {m.pluggy_manager.get_name(p) for p in m.pluggy_manager.get_plugins()}
    builtin = {n for n in names if "benchharness_builtins" in n}
    assert builtin == {
        f"{ep} = benchharness_builtins.{ep}"
        for ep in ("backends", "inhand_tasks", "robots", "rubiks_tasks", "sensors", "strategies")
    }
    assert {it.distribution for it in m.items()} == {"benchharness"}


# -- the block list ----------------------------------------------------------------------------

EXPLODES = """
raise RuntimeError("this plugin must not even be imported")
"""


def test_disabled_plugin_is_not_imported_and_is_reported(site, monkeypatch):
    make_distribution(
        site, "thirdparty-good", {"good": "thirdparty_good"}, {"thirdparty_good": GOOD}
    )
    make_distribution(
        site, "thirdparty-bomb", {"bomb": "thirdparty_bomb"}, {"thirdparty_bomb": EXPLODES}
    )
    monkeypatch.setenv("BENCHHARNESS_DISABLED_PLUGINS", " bomb , good,nosuch")
    m = PluginManager()
    m.load_entry_points()
    assert m.errors == []  # the bomb was never imported
    assert "thirdparty_bomb" not in sys.modules
    assert {(d.entry_point, d.distribution) for d in m.disabled} == {
        ("bomb = thirdparty_bomb", "thirdparty-bomb"),
        ("good = thirdparty_good", "thirdparty-good"),
    }
    assert m.disabled_unmatched == ["nosuch"]
    assert "pr2" in m.names("robot")  # the built-ins still load
    with pytest.raises(PluginNotFoundError) as info:
        m.get("robot", "thirdparty-arm")
    assert "disabled by BENCHHARNESS_DISABLED_PLUGINS" in str(info.value)
    assert "good = thirdparty_good" in str(info.value)

    monkeypatch.delenv("BENCHHARNESS_DISABLED_PLUGINS")
    m = PluginManager()
    m.load_entry_points()
    assert m.get("robot", "thirdparty-arm").distribution == "thirdparty-good"
    assert any(e.distribution == "thirdparty-bomb" for e in m.errors)


def test_plugins_command_lists_disabled(monkeypatch):
    import json

    from click.testing import CliRunner

    from benchharness.cli.plugins import plugins_cmd

    monkeypatch.setenv("BENCHHARNESS_DISABLED_PLUGINS", "sensors,typo_name")
    get_manager(reload=True)
    try:
        out = CliRunner().invoke(plugins_cmd, ["--json"], catch_exceptions=False)
        data = json.loads(out.output)
        assert data["disabled"] == [
            {
                "entry_point": "sensors = benchharness_builtins.sensors",
                "distribution": "benchharness",
            }
        ]
        assert data["disabled_unmatched"] == ["typo_name"]
        assert not [i for i in data["items"] if i["kind"] == "sensor"]
        text = CliRunner().invoke(plugins_cmd, [], catch_exceptions=False).output
        assert "disabled:" in text and "'sensors = benchharness_builtins.sensors'" in text
        assert "'typo_name', which is no entry point" in text
    finally:
        monkeypatch.delenv("BENCHHARNESS_DISABLED_PLUGINS")
        get_manager(reload=True)


# -- robot metadata comes from the robot's config -------------------------------------------------


def _movable_joints(urdf: Path) -> set[str]:
    import xml.etree.ElementTree as ET

    return {
        j.get("name", "")
        for j in ET.parse(urdf).getroot().iter("joint")
        if j.get("type") != "fixed"
    }


@pytest.mark.parametrize(
    ("name", "module", "config"),
    [
        ("pr2", "pr2", "pr2_config"),
        ("herb", "herb", "herb_config"),
        ("allegro", "allegro", "allegro_config"),
        ("pr2-gripper", "pr2_gripper", "pr2_gripper_config"),
    ],
)
def test_robot_meta_matches_config_and_urdf(name, module, config):
    """DOF = the URDF's movable joints (an independent count) less the fingertip joints a linkage
    moves (the PR2's four-bar fingertips follow their fingers), groups = the config's groups."""
    import importlib

    from benchharness.paths import data_root

    cfg = getattr(importlib.import_module(f"benchharness.robots.{module}"), config)()
    meta = get_manager(reload=True).get("robot", name).meta
    urdf = data_root() / meta["urdf"]
    assert urdf.resolve() == Path(cfg.urdf).resolve()
    followers = {k.follower for g in cfg.grippers for k in g.linkages}
    assert followers <= _movable_joints(urdf)
    assert meta["dof"] == len(_movable_joints(urdf) - followers)
    assert meta["groups"] == list(cfg.groups())
    assert {j for g in cfg.groups().values() for j in g} | followers == _movable_joints(urdf)


def test_listing_robots_reads_configs_without_torch():
    import subprocess

    code = (
        "import sys, json\n"
        "from benchharness.plugin import get_manager\n"
        "print(json.dumps([it.meta['dof'] for it in get_manager().items('robot')]))\n"
        "heavy = {m.split('.')[0] for m in sys.modules} & {'torch', 'pybullet', 'sapien'}\n"
        "print(','.join(sorted(heavy)))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.splitlines()
    assert out[0] == "[19, 30, 16, 8]"
    assert out[1:] == [""], f"reading robot metadata imported {out[1:]}"


def test_lazy_meta_is_read_once():
    calls = []

    def meta():
        calls.append(1)
        return {"dof": 3}

    class P:
        @hookimpl
        def benchharness_robots(self):
            return [Registration("lazy-arm", lambda: None, "lazy", meta)]

    m = PluginManager()
    m.register_module(P(), entry_point="p = p", distribution="p-dist")
    assert calls == []  # registering does not build the config
    item = m.get("robot", "lazy-arm")
    assert item.meta == {"dof": 3} and item.describe()["meta"] == {"dof": 3}
    assert calls == [1]


# -- strategies declare the robots they drive; a mismatch is refused before any trial -----------


def test_every_builtin_strategy_declares_registered_robots():
    from benchharness.runner.contract import declared_robots

    m = get_manager(reload=True)
    robots = set(m.names("robot"))
    declared = {it.name: declared_robots(it.meta) for it in m.items("strategy")}
    assert all(declared.values()), declared
    assert all(set(r) <= robots for r in declared.values() if r), declared
    assert declared["sensor-aided"] == ("pr2",)
    assert declared["relaxed-rigidity"] == ("allegro",)
    assert declared["push-grasp"] == ("herb",)
    assert declared["dmg"] == declared["pivoting"] == ("pr2-gripper",)


@pytest.mark.parametrize(
    ("task", "robot", "strategy", "drives"),
    [
        ("Rubiks-1-5", "allegro", "sensor-aided", "pr2"),
        ("Rubiks-1-5", "pr2", "relaxed-rigidity", "allegro"),
        ("inhand-level1", "pr2", "relaxed-rigidity", "allegro"),
    ],
)
def test_run_refuses_a_robot_the_strategy_does_not_drive(tmp_path, task, robot, strategy, drives):
    from click.testing import CliRunner

    from benchharness.cli.run import run

    store = tmp_path / "results.sqlite"
    args = ["--task", task, "--robot", robot, "--strategy", strategy, "--store", str(store)]
    r = CliRunner().invoke(run, [*args, "--workers", "0", "--no-progress"])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert lines == [
        f"error: --robot {robot!r}: strategy {strategy!r} drives only these robots: {drives}"
    ]
    assert not store.exists()  # refused before the store was opened, so nothing was stored


def test_check_drives_accepts_declared_and_undeclared():
    from benchharness.runner.contract import check_drives

    check_drives("s", {"robots": ["pr2", "herb"]}, "herb")
    check_drives("s", {}, "anything")  # no declaration: any robot
    with pytest.raises(ValueError, match="drives only these robots: pr2, herb$"):
        check_drives("s", {"robots": ["pr2", "herb"]}, "allegro")
    with pytest.raises(TypeError):
        check_drives("s", {"robots": "pr2"}, "pr2")  # a string is not a list of names


def test_docs_mismatch_example_prints_what_the_page_shows(tmp_path):
    """The ``benchharness run`` example in docs/plugins.md, run as written (store in tmp)."""
    import shlex

    from click.testing import CliRunner

    from benchharness.cli.run import run

    doc = (Path(__file__).resolve().parents[1] / "docs" / "plugins.md").read_text()
    lines = doc.splitlines()
    (k,) = [i for i, line in enumerate(lines) if line.startswith("$ benchharness run ")]
    argv = shlex.split(lines[k])[3:]
    store = tmp_path / "r.sqlite"
    r = CliRunner().invoke(run, [*argv, "--store", str(store)])
    assert r.exit_code == 2
    assert r.output.strip() == lines[k + 1]
    assert not store.exists()
