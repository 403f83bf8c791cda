"""``zenav bench nav``: the planners on the same seeded random worlds, through the whole
service stack.

Worlds come from :func:`zenav.sim.generate.random_scenario` (static clutter; crossing,
head-on and overtaking movers; mixed; a circle-crossing crowd), ``--worlds`` of each
family from seed ``--seed`` on, written as scenario files. Each (planner, world) is one
run through ``zenav run``'s path (:mod:`zenav.batch`), ``--jobs`` at a time; a run whose
``run.json`` is already in ``--out`` is not repeated. Per planner: success, collision and
timeout rates, mean time to goal and path length on the worlds that every planner
solved, minimum clearance, and decisions (planner events) per run.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from zenav import argtypes
from zenav.batch import (
    DEFAULT_VERIFY,
    Job,
    add_verify_argument,
    default_jobs,
    run_batch,
    verified_note,
    verify_count,
)
from zenav.bench.common import machine, words
from zenav.bench.escape import first_in_view, no_escape
from zenav.engine import ENGINES
from zenav.sim.generate import FAMILIES, random_scenario
from zenav.sim.scenario import Scenario, dump_scenario, load_scenario
from zenav.sim.unseen import CLASSES, FAMILY_PREFIX, WALKER_CLASSES, solvable, unseen_scenario

TARGET_SUCCESS = 0.98  # the paper planner, on every family
STILL_LIMIT = 10.0  # s: a run must not end with the robot standing this long while a way exists
STILL_RADIUS = 0.05  # m: "standing still" = within this of where the run ended
UNSEEN = tuple(FAMILY_PREFIX + c for c in CLASSES)  # scenes of the classes
WALKERS = tuple(FAMILY_PREFIX + c for c in WALKER_CLASSES)  # ORCA walkers between walls
GROUPS = {"unseen": UNSEEN, "walkers": WALKERS}  # --families names that stand for several
KNOWN = FAMILIES + UNSEEN + WALKERS


def world(family: str, seed: int) -> Scenario:
    """The scene of ``family`` for ``seed``: a random world or an unseen class scene."""
    if family.startswith(FAMILY_PREFIX):
        return unseen_scenario(family.removeprefix(FAMILY_PREFIX), seed)
    return random_scenario(family, seed)


def write_worlds(families: Sequence[str], count: int, seed: int, directory: Path,
                 fov_deg: float | None = None) -> list[Path]:
    """The scenario files; ``fov_deg``: every world's laser field of view instead of its
    own (the paper's 180° unless a family says otherwise)."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for family in families:
        for s in range(seed, seed + count):
            path = directory / f"{family}-{s}.yaml"
            scene = world(family, s)
            if fov_deg is not None:
                data = scene.model_dump(mode="json", exclude_none=True)
                data["laser"]["fov_deg"] = fov_deg
                scene = Scenario.model_validate(data)
            paths.append(dump_scenario(scene, path))
    return paths


@dataclass
class PlannerSummary:
    planner: str
    runs: int
    reached: int
    collisions: int
    timeouts: int
    errors: int
    mean_time: float  # on worlds every planner solved
    mean_path: float
    common: int  # how many such worlds
    min_clearance: float  # worst over the runs that did not collide
    median_clearance: float
    decisions: float  # planner events per run
    stuck: list[str]  # runs not reached that ended standing > STILL_LIMIT with a way known
    hit_unwarned: list[str]  # collisions no scan could have warned of (``no_warning``)
    hit_no_escape: list[str]  # the others with no way out once seen (``escape.no_escape``)

    def rate(self, count: int) -> float:
        return count / self.runs if self.runs else math.nan


def family_of(name: str) -> str:
    return name.rsplit("-", 1)[0]


def still_at_end(trajectory: Sequence[Sequence[float]]) -> float:
    """How long (s) the robot stood within ``STILL_RADIUS`` of where the run ended, up to
    the end (rows ``[t, x, y, heading, speed]`` of the run record)."""
    if not trajectory:
        return 0.0
    t_end, x_end, y_end = trajectory[-1][:3]
    since = t_end
    for row in reversed(trajectory):
        if math.hypot(row[1] - x_end, row[2] - y_end) > STILL_RADIUS:
            break
        since = row[0]
    return float(t_end - since)


def never_in_view(scenario: Scenario, record: dict[str, Any]) -> bool:
    """Whether the run ended in contact with an obstacle whose centre was never inside
    the laser's field (within ``fov_deg / 2`` of the heading and ``max_range``) at any
    tick of the run (``escape.first_in_view``). Occlusion is ignored, so this is what the
    laser could not have seen even with nothing in the way."""
    index = record.get("collided_with")
    if record.get("outcome") != "collision" or index is None or not record.get("trajectory"):
        return False
    return first_in_view(scenario, record, index) is None


def appeared_at_contact(scenario: Scenario, record: dict[str, Any]) -> bool:
    """Whether the run ended in contact with an obstacle that appeared (its ``appear``
    time, above 0) less than one laser period before the contact: the first scan that
    could show it came with the contact or after it, so no planner had a scan to act
    on. A scenario's obstacle appears where its file puts it, whatever the robot has
    done, so it can come down on the robot."""
    index = record.get("collided_with")
    if record.get("outcome") != "collision" or index is None:
        return False
    appear = float(scenario.obstacles[index].appear)
    period = 1.0 / scenario.laser.rate_hz
    return appear > 0.0 and float(record["time"]) - appear < period


def no_warning(scenario: Scenario, record: dict[str, Any]) -> bool:
    """Whether the run ended in a collision no scan could have warned of: with an
    obstacle never in the laser's field (``never_in_view``), or one that appeared at
    the contact (``appeared_at_contact``)."""
    return never_in_view(scenario, record) or appeared_at_contact(scenario, record)


UNWARNED = "unwarned"
NO_WAY_OUT = "no way out"
WAY_OUT = "way out"


def collision_kind(scenario: Scenario, record: dict[str, Any]) -> str | None:
    """What a collision left the robot: ``UNWARNED`` (no scan could have warned of the
    obstacle: :func:`no_warning`), ``NO_WAY_OUT`` (in view, but on a path of its own that
    left no way out once a planner could act on it: :func:`zenav.bench.escape.no_escape`)
    or ``WAY_OUT``; None for a run that did not end in a collision. ``bench nav`` and
    ``bench crowd`` count their collisions by it."""
    if record.get("outcome") != "collision":
        return None
    if no_warning(scenario, record):
        return UNWARNED
    return NO_WAY_OUT if no_escape(scenario, record) else WAY_OUT


def summarise(records: list[dict[str, Any]], planners: Sequence[str],
              has_way: Callable[[str], bool] = lambda name: True,
              unwarned_hit: Callable[[dict[str, Any]], bool] = lambda record: False,
              no_escape_hit: Callable[[dict[str, Any]], bool] = lambda record: False,
              ) -> tuple[list[PlannerSummary], dict[str, dict[str, float]]]:
    """Per planner and per family; ``has_way``: whether a world (by name) has a way for
    the robot's disc on its static geometry (a run stuck there was the planner's);
    ``unwarned_hit``: whether a run ended hit by something no scan could warn of;
    ``no_escape_hit``: whether it ended hit by a mover it had no way out from once seen."""
    by_planner: dict[str, list[dict[str, Any]]] = {p: [] for p in planners}
    for r in records:
        by_planner.setdefault(r["planner"], []).append(r)
    worlds = {r["scenario"] for r in records}
    solved_by_all = {w for w in worlds if all(
        any(r["scenario"] == w and r["outcome"] == "reached" for r in by_planner[p])
        for p in planners)}
    summaries = []
    for p in planners:
        rs = by_planner[p]
        common = [r for r in rs if r["scenario"] in solved_by_all and r["outcome"] == "reached"]
        safe = [r["min_clearance"] for r in rs
                if r["outcome"] != "collision" and r.get("min_clearance") is not None]
        valid = [r for r in rs if r["outcome"] != "error"]
        summaries.append(PlannerSummary(
            planner=p, runs=len(valid),
            reached=sum(r["outcome"] == "reached" for r in rs),
            collisions=sum(r["outcome"] == "collision" for r in rs),
            timeouts=sum(r["outcome"] == "timeout" for r in rs),
            errors=sum(r["outcome"] == "error" for r in rs),
            mean_time=statistics.fmean(r["time"] for r in common) if common else math.nan,
            mean_path=statistics.fmean(r["path_length"] for r in common) if common else math.nan,
            common=len(common),
            min_clearance=min(safe) if safe else math.nan,
            median_clearance=statistics.median(safe) if safe else math.nan,
            decisions=statistics.fmean(len(r.get("events", [])) for r in valid) if valid
            else math.nan,
            stuck=[r["scenario"] for r in valid
                   if r["outcome"] not in ("reached", "collision")
                   and still_at_end(r.get("trajectory", [])) > STILL_LIMIT
                   and has_way(r["scenario"])],
            hit_unwarned=[r["scenario"] for r in valid
                          if r["outcome"] == "collision" and unwarned_hit(r)],
            hit_no_escape=[r["scenario"] for r in valid
                           if r["outcome"] == "collision" and not unwarned_hit(r)
                           and no_escape_hit(r)],
        ))
    families: dict[str, dict[str, float]] = {}
    for p in planners:
        for r in by_planner[p]:
            if r["outcome"] == "error":
                continue
            cell = families.setdefault(family_of(r["scenario"]), {})
            cell[p + "/n"] = cell.get(p + "/n", 0) + 1
            cell[p + "/ok"] = cell.get(p + "/ok", 0) + (r["outcome"] == "reached")
            cell[p + "/hit"] = cell.get(p + "/hit", 0) + (r["outcome"] == "collision")
    return summaries, families


def pct(part: float, whole: float) -> str:
    return "—" if not whole else f"{100 * part / whole:.0f} %"


def num(value: float, digits: int = 1) -> str:
    return "—" if math.isnan(value) else f"{value:.{digits}f}"


def tables(summaries: list[PlannerSummary], families: dict[str, dict[str, float]]) -> str:
    common = summaries[0].common if summaries else 0
    lines = [
        "| planner | runs | success | collision | … that no scan could warn of‡ | timeout | "
        "stood still at the end† | "
        "mean time to goal s* | mean path m* | min clearance m (worst / median) | "
        "decisions per run |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for s in summaries:
        errors = f" (+{s.errors} failed)" if s.errors else ""
        lines.append(
            f"| {s.planner} | {s.runs}{errors} | {pct(s.reached, s.runs)} | "
            f"{pct(s.collisions, s.runs)} | {len(s.hit_unwarned)} | {pct(s.timeouts, s.runs)} | "
            f"{len(s.stuck)} | "
            f"{num(s.mean_time)} | "
            f"{num(s.mean_path, 2)} | {num(s.min_clearance, 3)} / {num(s.median_clearance, 3)} | "
            f"{num(s.decisions)} |")
    lines.append("")
    lines.append(f"\\* on the {common} worlds every planner solved. Clearance over the runs "
                 "without a collision. † runs that did not reach the goal and ended with "
                 f"the robot standing (within {STILL_RADIUS:g} m) for more than "
                 f"{STILL_LIMIT:g} s in a world where its disc has a way round the static "
                 "obstacles (a flood fill). ‡ collisions (a count) with an obstacle whose "
                 "centre was never within the laser's field of view and range at any tick "
                 "of the run, occlusion aside, or that appeared less than one laser "
                 "period before the contact: no planner that acts on the scans could "
                 "have known of it in time.")
    planners = [s.planner for s in summaries]
    lines += ["", "| family | " + " | ".join(f"{p}: success (collisions)" for p in planners)
              + " |", "|---|" + "---|" * len(planners)]
    for family in KNOWN:
        if family not in families:
            continue
        cell = families[family]
        lines.append(f"| {family} | " + " | ".join(
            f"{pct(cell.get(p + '/ok', 0), cell.get(p + '/n', 0))} "
            f"({int(cell.get(p + '/hit', 0))}/{int(cell.get(p + '/n', 0))})" for p in planners)
            + " |")
    return "\n".join(lines)


def goal_lines(summaries: list[PlannerSummary], families: dict[str, dict[str, float]]) -> str:
    """The navigation issue's targets for the paper planner: success on every family
    run, and no run ended standing while a way existed; then how it compares with the
    baselines run beside it."""
    paper = next((s for s in summaries if s.planner == "paper"), None)
    if paper is None:
        return ""
    rates = {f: cell["paper/ok"] / cell["paper/n"] for f, cell in families.items()
             if cell.get("paper/n")}
    short = [f"{f} {100 * r:.0f} %" for f, r in rates.items() if r < TARGET_SUCCESS]
    # Each half of the goal carries its own verdict: one verdict after the second half
    # read as if it judged that half alone.
    success_met = bool(rates) and not short
    lines = [f"Goal: paper planner ≥ {100 * TARGET_SUCCESS:.0f} % success on every family, "
             f"and no run ending with the robot standing for more than {STILL_LIMIT:g} s "
             f"while a way existed — lowest family "
             + (f"{min(rates, key=lambda f: rates[f])} {100 * min(rates.values()):.0f} %"
                if rates else "—")
             + (f" (short: {', '.join(short)})" if short else "")
             + f" ({'met' if success_met else 'NOT met'})"
             + f"; stood still: {len(paper.stuck)}"
             + (f" ({', '.join(paper.stuck)})" if paper.stuck else "")
             + f" ({'NOT met' if paper.stuck else 'met'})."]
    if paper.collisions:
        lines.append("Collisions no scan could have warned of (never in the laser's field "
                     "of view, or appeared at the contact): "
                     f"{len(paper.hit_unwarned)} of {paper.collisions}"
                     + (f" ({', '.join(paper.hit_unwarned)})" if paper.hit_unwarned else "")
                     + ".")
        warned = paper.collisions - len(paper.hit_unwarned)
        if warned:
            lines.append(
                "Of the others, with a mover whose path does not depend on the robot (the "
                "world's own, or a walker blind to it) that left the robot no way out once "
                "a planner could act on it (standing, or any heading at its top speed, in "
                "open space with the mover's true path known: "
                f"`zenav.bench.escape`): {len(paper.hit_no_escape)} of {warned}"
                + (f" ({', '.join(paper.hit_no_escape)})" if paper.hit_no_escape else "")
                + ".")
    others = [s for s in summaries if s.planner != "paper"]
    if others:
        ahead = all(paper.rate(paper.reached) > s.rate(s.reached) for s in others)
        lines.append(f"Ahead of every baseline on success rate: "
                     f"{paper.rate(paper.reached) * 100:.0f} % vs "
                     + ", ".join(f"{s.planner} {s.rate(s.reached) * 100:.0f} %"
                                 for s in others)
                     + f" ({'yes' if ahead else 'no'}).")
    return "\n\n".join(lines)


def plot(summaries: list[PlannerSummary], families: dict[str, dict[str, float]],
         path: Path) -> None:
    """nav.png: outcomes per planner, success per world family."""
    from zenav.plot import draw_bench_chart

    planners = [s.planner for s in summaries]
    outcomes = {"reached": [s.rate(s.reached) for s in summaries],
                "timeout": [s.rate(s.timeouts) for s in summaries],
                "collision": [s.rate(s.collisions) for s in summaries]}
    success = {f: [100 * families[f].get(p + "/ok", 0) / families[f][p + "/n"]
                   if families[f].get(p + "/n", 0) else 0.0 for p in planners]
               for f in KNOWN if f in families}
    draw_bench_chart(planners, outcomes, success, path)


def expand_families(names: Sequence[str]) -> list[str]:
    """The world families ``names`` stand for: each a family of :data:`KNOWN`, or a group
    of :data:`GROUPS` (``unseen``, ``walkers``) for its families; ValueError on any other
    name, or on none."""
    families = [f for name in names for f in GROUPS.get(name, (name,))]
    bad = [f for f in families if f not in KNOWN]
    if bad or not families:
        raise ValueError(f"unknown family {', '.join(bad) or '(none given)'}; choose from "
                         f"{', '.join(KNOWN)}, unseen (the issue's classes) or walkers "
                         f"(the {', '.join(WALKERS)} classes)")
    return families


def run_nav(planners: Sequence[str], worlds: int, seed: int, out: Path,
            families: Sequence[str] = FAMILIES, jobs: int = 2,
            progress: bool = True, echo: Callable[[str], None] = print,
            engine: str = "inprocess", verify: int = DEFAULT_VERIFY,
            fov_deg: float | None = None, reuse: bool = False) -> str:
    """Write the worlds, run every planner on each, print and write the report.
    ``reuse``: a run whose ``run.json`` is already under ``out`` is not run again."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from zenav.services.runner import PLANNERS

    unknown = [p for p in planners if p not in PLANNERS]
    if unknown or not planners:
        raise ValueError(f"unknown planner {', '.join(unknown) or '(none given)'}; choose "
                         f"from {', '.join(PLANNERS)}")
    families = expand_families(families)
    if worlds < 1:
        raise ValueError(f"--worlds must be >= 1 (got {worlds})")
    if jobs < 1:
        raise ValueError(f"--jobs must be >= 1 (got {jobs})")
    if fov_deg is not None and not (0 < fov_deg <= 360 and (2 * fov_deg).is_integer()):
        raise ValueError(f"--fov must be in (0, 360] in half degrees (got {fov_deg:g})")
    out.mkdir(parents=True, exist_ok=True)
    paths = write_worlds(families, worlds, seed, out / "worlds", fov_deg)
    job_list = [Job(f"{p}/{w.stem}", w, out / "runs" / p / w.stem, planner=p)
                for w in paths for p in planners]
    records: list[dict[str, Any]] = []
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), TimeRemainingColumn(), disable=not progress,
                  transient=False) as bar:
        task = bar.add_task("zenav bench nav", total=len(job_list))

        def done(job: Job, record: dict[str, Any]) -> None:
            records.append(record)
            reached = sum(r["outcome"] == "reached" for r in records)
            bar.update(task, advance=1, description=f"{reached}/{len(records)} reached; "
                       f"{job.planner} {job.name}: {record['outcome']}")

        batch = run_batch(job_list, jobs, done, log_level="WARNING", reuse=reuse,
                          keep_going=True, engine=engine, verify=verify,
                          picture=engine == "stack", echo=echo)
    for r in records:
        if r["outcome"] == "error":
            echo(f"run failed: {r['planner']} {r['scenario']}: {r.get('error')}")
    world_files = {p.stem: p for p in paths}  # the flood fill only for runs that stood

    def has_way(name: str) -> bool:
        return name not in world_files or solvable(load_scenario(world_files[name]))

    # Each collision judged once, its world read once.
    kinds = {id(r): collision_kind(load_scenario(world_files[r["scenario"]]), r)
             for r in records
             if r["outcome"] == "collision" and r["scenario"] in world_files}
    summaries, per_family = summarise(
        records, planners, has_way,
        unwarned_hit=lambda record: kinds.get(id(record)) == UNWARNED,
        no_escape_hit=lambda record: kinds.get(id(record)) == NO_WAY_OUT)
    command = (f"zenav bench nav --planners {','.join(planners)} --worlds {worlds} "
               f"--seed {seed}" + ("" if tuple(families) == FAMILIES else
                                   f" --families {','.join(families)}")
               + ("" if fov_deg is None else f" --fov {fov_deg:g}")
               + (" --reuse" if reuse else ""))
    report = (f"# zenav bench nav\n\n`{command}`\n\n"
              f"{datetime.now().astimezone():%Y-%m-%d %H:%M %Z}, {machine()}; "
              f"{len(paths)} worlds ({worlds} per family: {', '.join(families)}"
              f"{'' if fov_deg is None else f'; laser {fov_deg:g}°'}), "
              f"{jobs} runs at a time ({engine} engine{verified_note(batch)})\n\n"
              f"{tables(summaries, per_family)}\n\n"
              f"{goal_lines(summaries, per_family)}\n")
    (out / "nav.md").write_text(report)
    (out / "nav.json").write_text(json.dumps(
        [{k: v for k, v in r.items() if k != "trajectory"} for r in records], indent=1))
    plot(summaries, per_family, out / "nav.png")
    echo(report)
    echo(f"wrote {out / 'nav.md'}, {out / 'nav.png'}, {out / 'nav.json'}")
    return report


def _command(args: argparse.Namespace) -> int:
    try:
        verify = verify_count(args.engine, args.verify)
        run_nav(words(args.planners), args.worlds, args.seed, args.out,
                families=words(args.families), jobs=args.jobs,
                progress=not args.no_progress, engine=args.engine, verify=verify,
                fov_deg=args.fov, reuse=args.reuse)
    except ValueError as exc:
        print(f"zenav bench nav: {exc}", file=sys.stderr)
        return 2
    return 0


def add_command(kinds: Any) -> None:
    """``zenav bench nav`` (``kinds``: the subcommands of ``zenav bench``)."""
    nav = kinds.add_parser("nav", help="planners on seeded random worlds (in-process "
                           "engine, a sample re-run through the stack)")
    nav.add_argument("--planners", default="paper,vfh,dwa,apf",
                     help="comma-separated planner names (default paper,vfh,dwa,apf)")
    nav.add_argument("--worlds", type=int, default=5, help="worlds per family (default 5)")
    nav.add_argument("--seed", type=argtypes.non_negative_int, default=0,
                     help="first seed (default 0)")
    nav.add_argument("--families", default=",".join(FAMILIES),
                     help=f"comma-separated world families (default {','.join(FAMILIES)}); "
                     f"also {', '.join(UNSEEN)}, or unseen for all of those; "
                     f"{', '.join(WALKERS)} (ORCA walkers between walls), or walkers")
    nav.add_argument("--jobs", type=int, default=default_jobs(),
                     help="runs at a time (default: the number of cores)")
    nav.add_argument("--engine", choices=ENGINES, default="inprocess",
                     help="inprocess (default): the services in one process per run, "
                     "worker processes in parallel; stack: six processes over Zenoh per run")
    add_verify_argument(nav)
    nav.add_argument("--out", type=argtypes.path, default=Path("out/bench-nav"),
                     help="directory for the worlds, runs, nav.md, nav.png, nav.json "
                     "(default out/bench-nav)")
    nav.add_argument("--fov", type=float, default=None,
                     help="every world's laser field of view, degrees (default: each "
                     "world's own, the paper's 180; 360 shows what the 180° laser "
                     "cannot see)")
    nav.add_argument("--reuse", action="store_true",
                     help="take a run.json already under --out as that run's record "
                     "(finish an interrupted sweep; by default every run is made again)")
    nav.add_argument("--no-progress", action="store_true", help="no progress bar")
    nav.set_defaults(func=_command)
