"""Parameter profiles: one named set of overrides per profile, valid for every service it
names, applied by zenav run and shown by zenav params; and the planner rules the paper
profile switches on (Algorithm 1's one threat per cycle and V_R - dV_R)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from zenav.services.config import ConfigError, resolve
from zenav.services.planner.decide import Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle
from zenav.services.profiles import PROFILES, apply_profile, profile_layer, profile_values
from zenav.services.runner import service_params

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", list(PROFILES))
def test_every_override_is_a_valid_parameter(name: str) -> None:
    for service, values in PROFILES[name].items():
        model = service_params(service, "paper")
        assert set(values) <= set(model.model_fields), service
        params, settings = resolve(model, [profile_layer(name, service)])
        for setting in settings:
            if setting.name in values:
                assert setting.origin == "profile" and setting.source == f"profile {name}"
                assert getattr(params, setting.name) == values[setting.name]


def test_the_paper_profile_is_the_papers_rules() -> None:
    assert profile_values("paper", "perception") == {"gap_floor": 0.0, "min_beams": 1,
                                                     "edge_inset": 0.0,
                                                     "motion_split_span": 0.0}
    tracking = profile_values("paper", "tracking")
    assert tracking["method"] == "paper" and tracking["compare_dt"] > 0.1
    planner = profile_values("paper", "planner")
    assert planner["threats_per_cycle"] == "one" and planner["slow_step"] > 0
    assert profile_values("zenav", "planner") == {}


def test_apply_profile_keeps_the_scenarios_values_and_spares_baselines() -> None:
    params: dict[str, dict[str, Any]] = {"perception": {"cell": 0.25, "gap_floor": 0.3},
                                         "planner": {"goal": [1, 2]}}
    apply_profile(params, "paper", "vfh")
    assert params["perception"] == {"cell": 0.25, "gap_floor": 0.3, "min_beams": 1,
                                    "edge_inset": 0.0, "motion_split_span": 0.0}
    assert params["planner"] == {"goal": [1, 2]}  # a baseline has none of these knobs
    assert params["tracking"]["method"] == "paper"


def test_an_unknown_profile_is_one_clear_error() -> None:
    params: dict[str, dict[str, object]] = {}
    with pytest.raises(ConfigError, match="unknown profile 'fast'; choose from zenav, paper"):
        apply_profile(params, "fast")
    assert params == {}


def test_zenav_run_refuses_an_unknown_profile_with_status_2(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "zenav", "run", str(ROOT / "sim/scenarios/a-no-obstacle.yaml"),
         "--out", str(tmp_path), "--profile", "fast"],
        capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == ("zenav run: unknown profile 'fast'; choose from zenav, "
                                   "paper")


def test_zenav_params_shows_the_profiles_origin() -> None:
    done = subprocess.run([sys.executable, "-m", "zenav", "params", "perception", "--profile",
                           "paper"], capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert "gap_floor: 0.0  # profile paper" in done.stdout
    assert "lambda_: 1.2  # default" in done.stdout


# --- Algorithm 1 in the planner -----------------------------------------------------------

BOX = Obstacle(id=1, kind="static", position=(2.0, 0.0), velocity=(0.0, 0.0), radius=0.2,
               cells=(4, 4, 0, 0))
# Crosses the robot's way at (1, 0) at 10 s, when the robot gets there (scenario (e)).
CROSSER = Obstacle(id=2, kind="dynamic", position=(1.0, -2.0), velocity=(0.0, 0.2),
                   radius=0.2, cells=(2, 2, -4, -4))


def planner(**changes: object) -> Planner:
    return Planner(Params(goal=(6.0, 0.0), start=(0.0, 0.0), confirm_time=0.0,
                          **changes))


def test_all_threats_at_once_is_h() -> None:
    decision = planner().step((0.0, 0.0, 0.0), [BOX, CROSSER], stamp=1.0)
    assert decision.scenario == "h"


def test_one_threat_per_cycle_answers_the_first_in_scan_order() -> None:
    """The crosser is 63 degrees right of the heading, the box straight ahead: the scan
    (right to left) meets the crosser first, so this cycle answers it alone."""
    decision = planner(threats_per_cycle="one").step((0.0, 0.0, 0.0), [BOX, CROSSER],
                                                     stamp=1.0)
    assert (decision.scenario, decision.obstacle) == ("e", 2)
    # the box alone, on its own cycle: Morphin
    alone = planner(threats_per_cycle="one").step((0.0, 0.0, 0.0), [BOX], stamp=1.0)
    assert (alone.scenario, alone.action) == ("b", "morphin")


def test_slow_step_takes_dv_r_off_each_cycle_and_recovers() -> None:
    """Algorithm 1: while the collision with the crosser is predicted, V_R = V_R - dV_R
    each cycle (0.1 -> 0.08 -> 0.06 ...), down to a stop; with nothing predicted, V_R."""
    p = planner(threats_per_cycle="one", slow_step=0.02, speed_check=False)
    speeds = [p.step((0.0, 0.0, 0.0), [CROSSER], stamp=1.0 + 0.1 * i).speed for i in range(6)]
    assert speeds == pytest.approx([0.08, 0.06, 0.04, 0.02, 0.0, 0.0])
    assert p.step((0.0, 0.0, 0.0), [], stamp=2.0).speed == pytest.approx(0.1)
