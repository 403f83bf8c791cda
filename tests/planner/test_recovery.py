"""The progress checker and the order of the recovery steps (pure)."""

from __future__ import annotations

from zenav.services.planner.recovery import Recovery, RecoverySettings

SETTINGS = RecoverySettings(progress_distance=0.5, progress_timeout=10.0,
                            stop_zone_timeout=5.0, wait_allowance=20.0, spin_angle=6.28,
                            backup_distance=0.3, backup_speed=0.05, wait_time=5.0,
                            max_rounds=2)


def feed(r: Recovery, t0: float, t1: float, to_go, waiting=False, refused=False) -> float | None:
    """Cycles every 0.1 s; the stamp at which recovery is asked for, else None."""
    t = t0
    while t < t1 - 1e-9:
        if r.watch(t, to_go(t), waiting, refused):
            return t
        t = round(t + 0.1, 6)
    return None


def test_steady_progress_never_asks_for_recovery() -> None:
    r = Recovery(SETTINGS)
    assert feed(r, 0.0, 100.0, lambda t: 10.0 - 0.1 * t) is None


def test_no_progress_for_the_timeout_asks_for_recovery() -> None:
    r = Recovery(SETTINGS)
    stalled = feed(r, 0.0, 30.0, lambda t: 5.0)
    assert stalled is not None and 10.0 <= stalled <= 10.2


def test_waiting_for_a_mover_is_not_a_lack_of_progress_up_to_the_allowance() -> None:
    r = Recovery(SETTINGS)
    assert feed(r, 0.0, 15.0, lambda t: 5.0, waiting=True) is None
    r = Recovery(SETTINGS)
    stalled = feed(r, 0.0, 60.0, lambda t: 5.0, waiting=True)
    assert stalled is not None and 29.9 <= stalled <= 30.3  # allowance 20 s + timeout 10 s


def test_the_stop_zone_refusing_motion_asks_for_recovery_sooner() -> None:
    r = Recovery(SETTINGS)
    stalled = feed(r, 0.0, 30.0, lambda t: 5.0, refused=True)
    assert stalled is not None and 5.0 <= stalled <= 5.2


def test_with_no_way_known_the_goal_is_unreachable_after_the_rounds() -> None:
    r = Recovery(SETTINGS)
    steps = []
    for k in range(9):
        step = r.start_next(float(k), (0.0, 0.0, 0.0), way_known=False)
        steps.append(step)
        if step is not None:
            r.finish(float(k), 5.0)
    assert steps == ["replan", "spin", "back_up", "wait"] * 2 + [None]
    assert r.unreachable


def test_progress_starts_the_sequence_afresh() -> None:
    r = Recovery(SETTINGS)
    feed(r, 0.0, 11.0, lambda t: 5.0)
    assert r.start_next(11.0, (0.0, 0.0, 0.0)) == "replan"
    r.finish(11.0, 5.0)
    assert feed(r, 11.0, 20.0, lambda t: 5.0 - (t - 11.0)) is None  # moving on again
    assert r.start_next(20.0, (0.0, 0.0, 0.0)) == "replan"


def test_while_a_way_is_known_the_rounds_go_on() -> None:
    r = Recovery(SETTINGS)
    steps = []
    for k in range(12):
        steps.append(r.start_next(float(k), (0.0, 0.0, 0.0), way_known=True))
        r.finish(float(k), 5.0)
    assert steps == ["replan", "spin", "back_up", "wait"] * 3
    assert not r.unreachable


def test_giving_up_ends_the_step_under_way_and_marks_the_goal_unreachable() -> None:
    r = Recovery(SETTINGS)
    assert r.start_next(0.0, (0.0, 0.0, 0.0)) == "replan"
    assert r.active is not None and not r.unreachable
    r.give_up()
    assert r.active is None and r.unreachable
