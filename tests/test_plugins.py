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
