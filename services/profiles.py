"""Named sets of parameter overrides: ``zenav`` (the code defaults) and ``paper``.

A profile is one place that says how each service departs from its defaults. ``paper``
runs every rule of the paper's Section 3 as written, and where the paper is silent it
makes the choice written beside each value below. ``zenav run --profile NAME``,
``zenav paper`` and ``zenav params NAME --profile NAME`` read the profile from here; it
is applied over the defaults and under the scenario, files and ``--set``.
"""

from __future__ import annotations

from typing import Any

from zenav.services.config import ConfigError, Layer

PAPER_COMPARE_PERIOD = 1.0
"""T, s: the paper's Eq. 15 and decision tree compare frame t with frame t - T, and the
paper never fixes T ("the time period of laser scanning"). At 10 Hz a 0.45 m/s walker
moves 0.09 cells per frame, under theta_delta = 0.4 cells, so with T = 0.1 s the tree
types almost no mover as dynamic. Typing accuracy against T (``zenav bench accuracy
--seeds 2 --compare-periods 0.1,0.3,0.5,1,1.5,2``, kept in docs/tracking-accuracy.txt),
at 0.01 m noise, robot still / driving: movers typed dynamic 0 / 0.2 % at T = 0.1 s,
24 / 22 % at 0.5 s, 72 / 78 % at 1 s, 81-88 % at 1.5 and 2 s; the heading error is
smallest at 1 s (median 14-15 degrees against 24-61 at 0.5, 1.5 and 2 s) and the speed
error too (median 19 %). T = 1 s: the most movers typed with the least error; beyond it
a mover's two positions are too far apart to be matched well."""

PROFILES: dict[str, dict[str, dict[str, Any]]] = {
    "zenav": {},
    "paper": {
        "perception": {
            "gap_floor": 0.0,  # Eq. 3 as written: theta = lambda rho sin(d_alpha)
            "min_beams": 1,  # a single beam is a cluster (the paper drops nothing)
            "edge_inset": 0.0,  # S_k from the points' cells as they fall (Eq. 2, Eq. 6)
            "motion_split_span": 0.0,  # a cluster is what Eq. 3 joins, movers and all
        },
        "tracking": {
            "method": "paper",  # the decision tree types, Eq. 15 moves
            "compare_dt": PAPER_COMPARE_PERIOD,  # T (paper silent), see above
            "memory": 0.0,  # the paper keeps no obstacle it cannot see
            "reacquire": 0.0,  # ... and calls every obstacle it sees again new
        },
        "planner": {
            "threats_per_cycle": "one",  # Algorithm 1: the first threat, then break
            # (e) when robot and crosser are at the PCP at the same time; the paper gives
            # "the same time" no width: each is at the PCP while within the clearance of
            # it, and the two intervals overlap (prediction.at_the_pcp_together).
            "meet_rule": "same_time",
            # Algorithm 1's V_R - Delta V_R. The paper gives no Delta V_R: 0.02 m/s per
            # cycle takes V_R = 0.1 m/s to a stop in 5 scans (0.5 s at 10 Hz).
            "slow_step": 0.02,
            "speed_check": False,  # no speed check against movers beyond the letter
            "fast_fallback": False,  # (f) is answered at V_R only
            "confirm_time": 0.0,  # a static obstacle is answered at once
            "threat_hysteresis": 0.0,  # no extra margin for an obstacle already answered
            # Eq. 17 with its three terms only: no side-switch or dead-end costs, Delta L
            # in a straight line, candidates as long as the centreline, the paper's fan.
            "switch_penalty": 0.0,
            "dead_end_penalty": 0.0,
            "around_obstacles": False,
            "extend_past": False,
            "escape_fan_deg": 85.0,  # = fan_max_deg: no wider escape fan
            "use_map": False,  # no map: the global path is the straight start-goal line
            "recovery": False,  # no progress checker, no recovery steps
            # No stepping aside for a walker between walls: the paper's (f) detour. (It
            # also needs the map, so with use_map off it could not act; said here so that
            # `zenav params planner --profile paper` shows the paper's value.)
            "give_way": False,
        },
    },
}
"""Per profile, per service, the parameters that differ from the code defaults."""

PROFILE_NAMES = tuple(PROFILES)
DEFAULT_PROFILE = "zenav"

# The planner overrides are the paper planner's parameters; a baseline planner gets none.
_PAPER_PLANNER = "paper"


def profile_values(name: str, service: str, planner: str = _PAPER_PLANNER) -> dict[str, Any]:
    """What profile ``name`` sets of one service's parameters (empty when nothing).

    Raises ConfigError for an unknown profile, naming the ones there are."""
    if name not in PROFILES:
        raise ConfigError(f"unknown profile {name!r}; choose from {', '.join(PROFILE_NAMES)}")
    if service == "planner" and planner != _PAPER_PLANNER:
        return {}
    return dict(PROFILES[name].get(service, {}))


def apply_profile(params: dict[str, dict[str, Any]], name: str,
                  planner: str = _PAPER_PLANNER) -> None:
    """Merge profile ``name`` into per-service parameters (as ``stack_params`` gives them);
    the values already there (the scenario's) win. Raises ConfigError for an unknown
    profile."""
    profile_values(name, "", planner)  # an unknown name raises before anything changes
    for service in PROFILES[name]:
        values = profile_values(name, service, planner)
        params[service] = {**values, **params.get(service, {})}


def profile_layer(name: str, service: str, planner: str = _PAPER_PLANNER) -> Layer:
    """What profile ``name`` sets of one service, as a layer over the defaults."""
    return Layer("profile", f"profile {name}", profile_values(name, service, planner))
