"""The in-hand paper's printed results, shown beside ours in ``benchharness table``.

Source: S. Cruciani, B. Sundaralingam, K. Hang, V. Kumar, T. Hermans,
D. Kragic, "Benchmarking In-Hand Manipulation", IEEE RA-L 2020.
Table II: real-robot Level I results on the Allegro hand (medians of all
trials; 500 trials per method). Table III: the DMG planner on four Level III
tasks (YuMi gripper). Units as printed: cm, %, s. (The Rubik's Table I is
data in ``tasks/rubiks/tiers.toml``, read through :mod:`benchharness.cube`.)
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["PLAN_TIME_S", "TABLE_II", "TABLE_III", "TABLE_III_ROWS"]

#: method -> {drops_percent, err_pos_cm, err_pos_percent, err_or_percent}
TABLE_II: Mapping[str, Mapping[str, float]] = {
    "point-contact": {
        "drops_percent": 5,
        "err_pos_cm": 1.69,
        "err_pos_percent": 36.81,
        "err_or_percent": 9.74,
    },
    "relaxed-position": {
        "drops_percent": 9,
        "err_pos_cm": 1.64,
        "err_pos_percent": 30.95,
        "err_or_percent": 10.43,
    },
    "relaxed-position-orientation": {
        "drops_percent": 7,
        "err_pos_cm": 1.54,
        "err_pos_percent": 29.19,
        "err_or_percent": 9.84,
    },
    "relaxed-rigidity": {
        "drops_percent": 0,
        "err_pos_cm": 1.32,
        "err_pos_percent": 28.67,
        "err_or_percent": 9.86,
    },
}

#: method -> median planning time (s) across all objects, Level I on the Allegro
#: (Sec. IV-A2's text, not Table II; IK-rigid was planned but not run on the robot)
PLAN_TIME_S: Mapping[str, float] = {
    "point-contact": 14.8,
    "ik-rigid": 4.4,
    "relaxed-position": 0.5,
    "relaxed-position-orientation": 0.3,
    "relaxed-rigidity": 0.5,
}

#: Table III rows in print order: key -> label
TABLE_III_ROWS: Mapping[str, str] = {
    "err_pos_cm": "err_pos (cm)",
    "err_pos_percent": "err_pos%",
    "err_or_percent": "err_or%",
    "g_euc_cm": "G_euc (cm)",
    "g_geo_cm": "G_geo (cm)",
    "g_min_cm": "G_min (cm)",
    "graph_time_s": "DMG (graph) time (s)",
    "plan_time_s": "plan time (s)",
}

#: object -> row key -> value (DMG method)
TABLE_III: Mapping[str, Mapping[str, float]] = {
    "gelatin box": {
        "err_pos_cm": 0.505,
        "err_pos_percent": 9.9,
        "err_or_percent": 0.016,
        "g_euc_cm": 1.125,
        "g_geo_cm": 1.127,
        "g_min_cm": 0.013,
        "plan_time_s": 0.023,
        "graph_time_s": 10.312,
    },
    "cracker box": {
        "err_pos_cm": 0.267,
        "err_pos_percent": 2.7,
        "err_or_percent": 0.044,
        "g_euc_cm": 0.862,
        "g_geo_cm": 0.862,
        "g_min_cm": 0.057,
        "plan_time_s": 0.004,
        "graph_time_s": 15.467,
    },
    "spatula": {
        "err_pos_cm": 0.513,
        "err_pos_percent": 8.8,
        "err_or_percent": 0.023,
        "g_euc_cm": 0.746,
        "g_geo_cm": 1.505,
        "g_min_cm": 0.034,
        "plan_time_s": 6.7e-05,
        "graph_time_s": 13.406,
    },
    "potted meat can": {
        "err_pos_cm": 0.610,
        "err_pos_percent": 11.0,
        "err_or_percent": 0.049,
        "g_euc_cm": 0.663,
        "g_geo_cm": 0.663,
        "g_min_cm": 0.004,
        "plan_time_s": 0.002,
        "graph_time_s": 18.295,
    },
}
