"""Accuracy of obstacle typing and mover speed / heading: the paper profile vs zenav's.

Simulated scans (the simulator's pure modules: scenario, world, raycast) of a small scene seen
from a robot that stands still or drives at full speed while turning. The scene has three
static obstacles and one mover at one of the paper's mixed-case speeds and directions
(Table 2: 450, 760, 510, 805 mm/s at alpha_o 80.83, 62.47, 91.05, 180.09 degrees). Each frame
goes through perception (``cluster_scan``) and the tracker.

Measured, per (robot motion, range noise, method):

* typing accuracy per obstacle type: over every frame in which the obstacle is seen (at
  least 3 beams hit it inside the window), after its first two such frames, the share of
  frames in which the nearest visible track is of the right type (no track = wrong);
* speed and heading error of the mover once it has been seen for 1 s: median and 95th
  percentile of |v - v_true| / v_true and of the heading error, and the share of frames
  within the targets (10 %, 5 degrees), whatever type the track had.

Targets (issue): >= 95 % correct type; speed within 10 % and heading within 5 degrees for a
mover seen for 1 s, at noise 0.01 m. Seeded: the same command prints the same table.

Run: ``zenav bench accuracy [--seeds N] [--duration S]`` (or ``python -m
zenav.bench.tracking_accuracy ...``).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from zenav import argtypes
from zenav.schemas.messages import LaserScan
from zenav.services.geometry import wrap_angle
from zenav.services.perception.clustering import cluster_scan
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.profiles import profile_values
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track, Tracker
from zenav.sim.raycast import cast_rays, simulate_scan
from zenav.sim.scenario import Scenario, parse_scenario
from zenav.sim.world import World, WorldSnapshot

# The paper's mixed case (Table 2): speed m/s and alpha_o degrees (clockwise from +y).
PAPER_MOVERS: tuple[tuple[float, float], ...] = (
    (0.45, 80.83),
    (0.76, 62.47),
    (0.51, 91.05),
    (0.805, 180.09),
)
TARGET_ACCURACY = 0.95
TARGET_SPEED_REL = 0.10
TARGET_HEADING_DEG = 5.0
SEEN_FOR = 1.0  # s: speed and heading are scored once a mover has been seen this long
SKIP_FRAMES = 2  # frames: typing is scored after an obstacle's first two frames
MIN_HIT_BEAMS = 3  # beams: an obstacle counts as seen in a frame with at least this many
MATCH_MARGIN = 0.35  # m: a track is an obstacle's when within its size + this of its centre

ROBOT_START = (5.0, 10.0)
ROBOT_SPEED = 0.2  # m/s: "full speed" (max_speed = 2 x the scenario's cruise speed 0.1)
TURN_AMPLITUDE = 0.5  # rad: the heading swings +-0.5 rad ...
TURN_RATE = 0.8  # rad/s: ... as 0.5 sin(0.8 t): yaw rate up to 0.4 rad/s
MOVER_VIA = (8.0, 10.2)  # m: every mover passes here half-way through the run


@dataclass(frozen=True)
class Method:
    """One configuration compared: a name, its perception and its tracking parameters."""

    name: str
    perception: PerceptionParams
    tracking: TrackingParams


def profile_method(profile: str, compare_dt: float | None = None,
                   name: str | None = None) -> Method:
    """Perception and tracking as parameter profile ``profile`` sets them (the one place,
    ``zenav.services.profiles``); ``compare_dt`` replaces its T."""
    tracking = profile_values(profile, "tracking")
    if compare_dt is not None:
        tracking["compare_dt"] = compare_dt
    return Method(name or profile, PerceptionParams(**profile_values(profile, "perception")),
                  TrackingParams(**tracking))


def methods() -> list[Method]:
    """The two profiles: ``paper`` (Eq. 3 alone, the decision tree and Eq. 15 over the
    profile's T) and ``zenav`` (the defaults: the motion cue and the smoothed estimate)."""
    return [profile_method("paper"), profile_method("zenav")]


def period_methods(periods: Sequence[float]) -> list[Method]:
    """The paper profile with each T (``compare_dt``) in ``periods``, seconds."""
    return [profile_method("paper", t, f"T={t:g}s") for t in periods]


COMPARE_PERIODS = (0.1, 0.3, 0.5, 1.0, 1.5, 2.0)
"""T, s: the periods the table of typing accuracy against T tries."""


def scenario_for(speed: float, alpha_o_deg: float, noise: float, seed: int) -> Scenario:
    """The bench scene with one mover of the given speed and paper direction alpha_o."""
    heading = math.radians(90.0 - alpha_o_deg)  # alpha_o is clockwise from +y
    vx, vy = speed * math.cos(heading), speed * math.sin(heading)
    return parse_scenario(
        {
            "name": "bench-tracking",
            "world": {"size": [20.0, 20.0], "cell": 0.5},
            "robot": {
                "start": list(ROBOT_START),
                "goal": [15.0, 10.0],
                "speed": 0.1,
                "radius": 0.2,
            },
            "laser": {"noise_std": noise},
            "obstacles": [
                {"shape": "box", "center": [7.5, 11.0], "size": [0.5, 0.5]},
                {"shape": "disc", "center": [7.0, 8.8], "radius": 0.25},
                {"shape": "box", "center": [9.0, 9.0], "size": [0.6, 0.4]},
                {"shape": "disc", "center": [0.0, 0.0], "radius": 0.2, "velocity": [vx, vy]},
            ],
            "seed": seed,
        },
        "<bench>",
    )


def _place_mover(scenario: Scenario, duration: float) -> Scenario:
    """Start the mover so that it passes MOVER_VIA at half the duration."""
    data = scenario.model_dump()
    mover = data["obstacles"][3]
    vx, vy = mover["velocity"]
    half = duration / 2.0
    mover["center"] = (MOVER_VIA[0] - vx * half, MOVER_VIA[1] - vy * half)
    return parse_scenario(data, "<bench>")


def robot_pose(t: float, moving: bool) -> tuple[float, float, float]:
    """Robot pose at time t: still at the start, or driving while its heading swings."""
    if not moving:
        return (ROBOT_START[0], ROBOT_START[1], 0.0)
    # Integrate the unicycle finely (1 ms) for the position along the swinging heading.
    steps = max(1, round(t / 0.001))
    ts = (np.arange(steps) + 0.5) * (t / steps)
    hs = TURN_AMPLITUDE * np.sin(TURN_RATE * ts)
    x = ROBOT_START[0] + float(np.sum(np.cos(hs))) * ROBOT_SPEED * t / steps
    y = ROBOT_START[1] + float(np.sum(np.sin(hs))) * ROBOT_SPEED * t / steps
    return (x, y, TURN_AMPLITUDE * math.sin(TURN_RATE * t))


@dataclass
class Tally:
    """Counts and error samples gathered over runs."""

    typed: dict[str, list[int]] = field(default_factory=lambda: {"static": [], "dynamic": []})
    speed_err: list[float] = field(default_factory=list)  # relative
    heading_err: list[float] = field(default_factory=list)  # degrees

    def add(self, other: Tally) -> None:
        for k, v in other.typed.items():
            self.typed[k].extend(v)
        self.speed_err.extend(other.speed_err)
        self.heading_err.extend(other.heading_err)


def run_case(scenario: Scenario, method: Method, moving: bool, duration: float) -> Tally:
    """Simulate one run and score it."""
    world = World.from_scenario(scenario)
    laser = scenario.laser
    angles = laser.angles_rad()
    rng = np.random.default_rng(scenario.seed)
    tracker = Tracker(method.tracking)
    smoothed = method.tracking.method == "smoothed"
    perceiver = Perceiver(method.perception) if smoothed else None
    tally = Tally()
    first_seen: dict[int, float] = {}
    frames_seen: dict[int, int] = {}
    r_w = method.perception.window_radius
    for i in range(round(duration * laser.rate_hz)):
        t = i * laser.period
        pose = robot_pose(t, moving)
        snap = world.snapshot(t)
        ranges = simulate_scan(
            pose[:2], pose[2], angles, snap, laser.max_range, laser.noise_std, rng
        )
        if perceiver is not None:  # the stack's perception: clustering + the motion cue
            scan = LaserScan(
                stamp=t, seq=i, frame="laser", angle_min=float(angles[0]),
                angle_max=float(angles[-1]), angle_increment=laser.angle_increment_rad,
                range_min=0.0, range_max=laser.max_range, ranges=ranges,
            )  # fmt: skip
            clusters = perceiver.process(scan, pose)
        else:  # the paper's: clustering alone
            clusters = cluster_scan(
                ranges, float(angles[0]), laser.angle_increment_rad, 0.0, laser.max_range,
                pose, method.perception,
            )  # fmt: skip
        tracks = tracker.update(t, pose, clusters)  # coasting tracks count: the planner gets them
        truth = np.asarray(
            cast_rays(pose[:2], pose[2] + angles, snap.disc_centers, snap.disc_radii,
                      snap.box_mins, snap.box_maxs, laser.max_range),
        )  # fmt: skip
        for k in range(snap.count):
            oid, centre, size, vel = _obstacle(snap, k)
            if _hit_beams(pose, angles, snap, k, truth, r_w, laser.max_range) < MIN_HIT_BEAMS:
                continue
            first_seen.setdefault(oid, t)
            frames_seen[oid] = frames_seen.get(oid, 0) + 1
            if frames_seen[oid] <= SKIP_FRAMES:
                continue
            track = _nearest(tracks, centre, size + MATCH_MARGIN)
            speed_true = math.hypot(vel[0], vel[1])
            kind = "dynamic" if speed_true > 0.0 else "static"
            tally.typed[kind].append(int(track is not None and track.kind == kind))
            if kind == "dynamic" and track is not None and t - first_seen[oid] >= SEEN_FOR - 1e-9:
                tally.speed_err.append(abs(track.speed - speed_true) / speed_true)
                err = math.atan2(vel[1], vel[0]) - track.heading
                tally.heading_err.append(abs(math.degrees(wrap_angle(err))))
    return tally


def _obstacle(
    snap: WorldSnapshot, k: int
) -> tuple[int, tuple[float, float], float, tuple[float, float]]:
    """(scenario id, centre, circumscribed radius, velocity) of the k-th existing obstacle."""
    nd = len(snap.disc_ids)
    if k < nd:
        c = snap.disc_centers[k]
        v = snap.disc_velocities[k]
        return (
            int(snap.disc_ids[k]),
            (float(c[0]), float(c[1])),
            float(snap.disc_radii[k]),
            (
                float(v[0]),
                float(v[1]),
            ),
        )
    j = k - nd
    lo, hi = snap.box_mins[j], snap.box_maxs[j]
    v = snap.box_velocities[j]
    half = 0.5 * float(np.hypot(*(hi - lo)))
    return (
        int(snap.box_ids[j]),
        (float(lo[0] + hi[0]) / 2.0, float(lo[1] + hi[1]) / 2.0),
        half,
        (float(v[0]), float(v[1])),
    )


def _hit_beams(
    pose: tuple[float, float, float],
    angles: npt.NDArray[np.float64],
    snap: WorldSnapshot,
    k: int,
    truth: npt.NDArray[np.float64],
    window: float,
    max_range: float,
) -> int:
    """Beams whose first hit (noise-free) is obstacle k and lies inside the window."""
    nd = len(snap.disc_ids)
    empty2 = np.zeros((0, 2))
    if k < nd:
        own = cast_rays(pose[:2], pose[2] + angles, snap.disc_centers[k : k + 1],
                        snap.disc_radii[k : k + 1], empty2, empty2, max_range)  # fmt: skip
    else:
        j = k - nd
        own = cast_rays(pose[:2], pose[2] + angles, empty2, np.zeros(0),
                        snap.box_mins[j : j + 1], snap.box_maxs[j : j + 1], max_range)  # fmt: skip
    hit = np.isfinite(own) & (own <= truth + 1e-9) & (own <= window)
    return int(np.count_nonzero(hit))


def _nearest(tracks: Sequence[Track], centre: tuple[float, float], reach: float) -> Track | None:
    best: Track | None = None
    best_d = reach
    for tr in tracks:
        d = math.hypot(tr.x - centre[0], tr.y - centre[1])
        if d <= best_d:
            best, best_d = tr, d
    return best


@dataclass(frozen=True)
class Row:
    """One line of the table."""

    motion: str
    noise: float
    method: str
    movers: tuple[float, ...]
    acc_static: float
    acc_dynamic: float
    speed_med: float
    speed_p95: float
    speed_ok: float
    heading_med: float
    heading_p95: float
    heading_ok: float


def evaluate(
    noises: Sequence[float] = (0.0, 0.01, 0.03),
    motions: Sequence[str] = ("still", "moving"),
    movers: Sequence[tuple[float, float]] = PAPER_MOVERS,
    seeds: int = 3,
    duration: float = 6.0,
    method_list: Sequence[Method] | None = None,
) -> list[Row]:
    """Run every combination and return one row per (motion, noise, method)."""
    rows: list[Row] = []
    for motion in motions:
        for noise in noises:
            for method in method_list if method_list is not None else methods():
                total = Tally()
                for speed, alpha in movers:
                    for seed in range(seeds):
                        sc = _place_mover(scenario_for(speed, alpha, noise, seed), duration)
                        total.add(run_case(sc, method, motion == "moving", duration))
                rows.append(_row(motion, noise, method.name, tuple(s for s, _ in movers), total))
    return rows


def _row(motion: str, noise: float, name: str, speeds: tuple[float, ...], t: Tally) -> Row:
    def share(xs: Sequence[int]) -> float:
        return float(np.mean(xs)) if xs else math.nan

    def pct(xs: Sequence[float], q: float) -> float:
        return float(np.percentile(xs, q)) if xs else math.nan

    def within(xs: Sequence[float], limit: float) -> float:
        return float(np.mean(np.asarray(xs) <= limit)) if xs else math.nan

    return Row(
        motion=motion, noise=noise, method=name, movers=speeds,
        acc_static=share(t.typed["static"]), acc_dynamic=share(t.typed["dynamic"]),
        speed_med=pct(t.speed_err, 50), speed_p95=pct(t.speed_err, 95),
        speed_ok=within(t.speed_err, TARGET_SPEED_REL),
        heading_med=pct(t.heading_err, 50), heading_p95=pct(t.heading_err, 95),
        heading_ok=within(t.heading_err, TARGET_HEADING_DEG),
    )  # fmt: skip


def format_table(rows: Sequence[Row]) -> str:
    """The rows as a fixed-width text table, targets in the header."""
    head = (
        f"{'robot':7} {'noise':>5} {'method':9} | {'static':>6} {'dynamic':>7} | "
        f"{'v med':>6} {'v p95':>6} {'v ok':>5} | {'hdg med':>7} {'hdg p95':>7} {'hdg ok':>6}"
    )
    targets = (
        f"{'target':7} {'':>5} {'':9} | {'>=95%':>6} {'>=95%':>7} | "
        f"{'':>6} {'<=10%':>6} {'':>5} | {'':>7} {'<=5deg':>7} {'':>6}"
    )
    lines = [head, targets, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.motion:7} {r.noise:5.2f} {r.method:9} | "
            f"{r.acc_static:6.1%} {r.acc_dynamic:7.1%} | "
            f"{r.speed_med:6.1%} {r.speed_p95:6.1%} {r.speed_ok:5.0%} | "
            f"{r.heading_med:7.2f} {r.heading_p95:7.2f} {r.heading_ok:6.0%}"
        )
    return "\n".join(lines)


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seeds", type=argtypes.positive_int, default=3,
                        help="runs per mover and setting (default 3)")
    parser.add_argument("--no-per-mover", action="store_true", help="skip the per-mover tables")
    parser.add_argument("--duration", type=argtypes.positive_float, default=6.0,
                        help="seconds per run (default 6)")
    parser.add_argument("--compare-periods", metavar="T,T,...", type=_periods, default=None,
                        help="instead: the paper profile's typing accuracy against T, the "
                             "period between the frames it compares (noise 0.01 m), e.g. "
                             + ",".join(f"{t:g}" for t in COMPARE_PERIODS))


def _periods(text: str) -> tuple[float, ...]:
    try:
        periods = tuple(float(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected seconds separated by commas, got {text!r}") from None
    if not periods or any(not (t >= 0.0 and math.isfinite(t)) for t in periods):
        raise argparse.ArgumentTypeError(f"periods must be finite and >= 0, got {text!r}")
    return periods


def report(args: argparse.Namespace) -> int:
    """Print the accuracy table (and one per mover speed at noise 0.01 m), or with
    ``--compare-periods`` the paper profile's accuracy against T."""
    if args.compare_periods is not None:
        print("The paper profile's typing accuracy and mover speed / heading errors against T,")
        print("the period between the two frames the decision tree and Eq. 15 compare. Movers")
        print(f"(m/s): {', '.join(f'{s:g}' for s, _ in PAPER_MOVERS)}; noise 0.01 m; "
              f"{args.seeds} seed(s), {args.duration:g} s per run, 10 Hz, 361 beams.\n")
        print(format_table(evaluate(noises=(0.01,), seeds=args.seeds, duration=args.duration,
                                    method_list=period_methods(args.compare_periods))))
        return 0
    print("Typing accuracy after each obstacle's first two frames; mover speed (relative) and")
    print("heading errors (degrees) once seen for 1 s: median, 95th percentile, share within")
    print(f"target. Movers (m/s): {', '.join(f'{s:g}' for s, _ in PAPER_MOVERS)}; "
          f"{args.seeds} seed(s), {args.duration:g} s per run, 10 Hz, 361 beams.\n")  # fmt: skip
    print(format_table(evaluate(seeds=args.seeds, duration=args.duration)))
    if args.no_per_mover:
        return 0
    print("\nPer mover at noise 0.01 m (speed m/s, alpha_o deg):")
    for speed, alpha in PAPER_MOVERS:
        rows = evaluate(
            noises=(0.01,), movers=((speed, alpha),), seeds=args.seeds, duration=args.duration
        )
        print(f"\n{speed:g} m/s, alpha_o {alpha:g} deg")
        print(format_table(rows))
    return 0




def main(argv: Sequence[str] | None = None) -> int:
    """``python -m zenav.bench.tracking_accuracy [--seeds N] [--duration S]``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    _add_arguments(parser)
    return report(parser.parse_args(argv))


def add_command(kinds: Any) -> None:
    """``zenav bench accuracy`` (``kinds``: the subcommands of ``zenav bench``)."""
    accuracy = kinds.add_parser("accuracy", help="obstacle typing, mover speed and heading "
                                "errors on simulated scans (paper vs zenav profile)")
    _add_arguments(accuracy)
    accuracy.set_defaults(func=report)


if __name__ == "__main__":
    raise SystemExit(main())
