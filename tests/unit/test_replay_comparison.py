"""The record/replay test's comparison of stateful stages tells a stage fed differently
(inconclusive), a sample the recorder missed (go on) and a real difference (failure)."""

from __future__ import annotations

from collections.abc import Mapping

from tests.integration.test_record_replay import compare_stateful

EVIDENCE = ("obstacles", "tracks", "cmd_vel")


def run(obstacles: list[float], tracks: Mapping[float, object],
        cmd_vel: list[float] | None = None) -> dict[str, dict[float, object]]:
    return {"obstacles": dict.fromkeys(obstacles), "tracks": dict(tracks),
            "cmd_vel": dict.fromkeys(cmd_vel if cmd_vel is not None else list(tracks))}


STAMPS = [0.1 * i for i in range(12)]
TRACKS = {s: f"tracks at {s}" for s in STAMPS}


def test_a_chain_the_recorder_missed_but_tracking_answered_does_not_end_the_comparison():
    live = run(STAMPS, TRACKS)
    replayed = run([s for s in STAMPS if s != STAMPS[3]], TRACKS)
    outcome = compare_stateful(live, replayed, "tracks", EVIDENCE)
    assert (outcome.compared, outcome.differs) == (12, None)


def test_outputs_that_differ_on_the_same_inputs_fail():
    replayed_tracks = {**TRACKS, STAMPS[5]: "something else"}
    outcome = compare_stateful(run(STAMPS, TRACKS), run(STAMPS, replayed_tracks), "tracks",
                               EVIDENCE)
    assert (outcome.compared, outcome.differs) == (5, STAMPS[5])


def test_an_output_one_run_lacks_makes_a_later_difference_inconclusive():
    replayed_tracks = {s: t for s, t in TRACKS.items() if s != STAMPS[2]}
    replayed_tracks[STAMPS[6]] = "state went another way"
    outcome = compare_stateful(run(STAMPS, TRACKS), run(STAMPS, replayed_tracks), "tracks",
                               EVIDENCE)
    assert (outcome.compared, outcome.differs) == (5, None)  # 0.0, 0.1, 0.3, 0.4, 0.5
    assert "lacked the tracks at 0.2" in outcome.stopped


def test_an_input_fed_in_one_run_only_ends_the_comparison():
    dropped = [s for s in STAMPS if s != STAMPS[4]]
    replayed = run(dropped, {s: TRACKS[s] for s in dropped})
    outcome = compare_stateful(run(STAMPS, TRACKS), replayed, "tracks", EVIDENCE)
    assert (outcome.compared, outcome.differs) == (4, None)
    assert "reached one run only" in outcome.stopped


def test_the_comparison_starts_at_the_first_output_both_runs_recorded():
    late = {s: t for s, t in TRACKS.items() if s >= STAMPS[2]}
    outcome = compare_stateful(run(STAMPS, TRACKS), run(STAMPS, late), "tracks", EVIDENCE)
    assert (outcome.compared, outcome.differs) == (10, None)
