"""Tier table against the paper's Table I, and registration through the plugin hook."""

from __future__ import annotations

import pytest

from benchharness.cube import RubiksTier, UnknownTierError, get_tier, load_tiers

# Table I of Yang et al., typed again here from the paper, independently of
# tasks/rubiks/tiers.toml: (dead reckoning PR2, sensor-aided PR2); None = "—".
TABLE_I = {
    "Rubiks-1-5": ((139.07, None), (126.67, None)),
    "Rubiks-1-10": ((248.43, None), (215.37, None)),
    "Rubiks-1-20": ((463.45, None), (447.96, None)),
    "Rubiks-1-50": (None, (1123.04, None)),
    "Rubiks-1-100": (None, (2207.97, None)),
    "Rubiks-1-200": (None, None),
    "Rubiks-5-5": ((113.35, 17.16), (113.81, 18.35)),
    "Rubiks-5-10": (None, (214.71, 30.39)),
    "Rubiks-5-20": (None, (416.61, 23.10)),
    "Rubiks-5-50": (None, None),
    "Rubiks-5-100": (None, None),
    "Rubiks-5-200": (None, None),
}


def test_twelve_tiers_in_the_papers_order():
    assert list(load_tiers()) == list(TABLE_I)


@pytest.mark.parametrize("name", list(TABLE_I))
def test_tier_matches_table_i(name):
    tier = get_tier(name)
    m, n = (int(x) for x in name.split("-")[1:])
    assert (tier.trials, tier.moves) == (m, n)
    assert [b.key for b in tier.baselines] == ["dead_reckoning_pr2", "sensor_aided_pr2"]
    for baseline, published in zip(tier.baselines, TABLE_I[name]):
        if published is None:
            assert not baseline.completed and baseline.mean_s is None and baseline.std_s is None
        else:
            assert baseline.completed and (baseline.mean_s, baseline.std_s) == published


def test_lookup_is_case_insensitive_and_lists_names_when_unknown():
    assert get_tier("rubiks-5-20").name == "Rubiks-5-20"
    with pytest.raises(UnknownTierError, match="tiers are Rubiks-1-5, Rubiks-1-10"):
        get_tier("Rubiks-2-20")


def test_summary_and_describe():
    tier = get_tier("Rubiks-5-20")
    assert tier.summary == "Rubik's cube: 5 trials × 20 moves"
    assert get_tier("Rubiks-1-5").summary == "Rubik's cube: 1 trial × 5 moves"
    assert [b.describe() for b in tier.baselines] == ["not completed", "416.61 / 23.10 s"]
    assert get_tier("Rubiks-1-20").baselines[0].describe() == "463.45 / — s"


def test_registered_through_the_plugin_hook():
    import benchharness_builtins.rubiks_tasks as module
    from benchharness.plugin import PluginManager

    pm = PluginManager()
    pm.register_module(module, entry_point="rubiks_tasks = benchharness_builtins.rubiks_tasks")
    assert pm.errors == []
    assert pm.names("task") == list(TABLE_I)
    item = pm.get("task", "Rubiks-5-20")
    assert item.summary == "Rubik's cube: 5 trials × 20 moves"
    assert item.meta["trials"] == 5 and item.meta["moves"] == 20
    tier = item.create()
    assert isinstance(tier, RubiksTier) and tier == get_tier("Rubiks-5-20")


def test_registered_through_the_entry_point():
    from benchharness.plugin import PluginManager

    pm = PluginManager()
    pm.load_entry_points()
    assert set(TABLE_I) <= set(pm.names("task"))
    assert not [e for e in pm.errors if "rubiks_tasks" in e.entry_point]
