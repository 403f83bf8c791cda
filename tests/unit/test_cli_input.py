"""Hostile and mistaken command-line input: YAML whose aliases would exhaust the memory,
values too long to quote, empty paths, unknown log levels, a service's own bad input.
Each is one line on stderr and status 2, found before anything starts or is created.

Every case runs the real ``zenav`` entry point (or the service's ``main``) in this
process; none opens a Zenoh session."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pytest
import yaml

from tests.unit.test_bad_input_table import SCENARIO, scenario_with
from tests.unit.test_startup_imports import loaded_by
from zenav.cli import build_light_parser, build_parser
from zenav.cli import main as zenav_main
from zenav.services import inputs
from zenav.services.inputs import ALIAS_NODES, AliasError, safe_load, shown
from zenav.services.runner import main as service_main

LAUGHS = "a0: &a0 [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]\n" for i in range(1, 9))
"""Nine anchors, each naming the one before nine times: 9^9 items once expanded."""


def one_line(capsys: pytest.CaptureFixture[str]) -> str:
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err[:2000]
    assert "Traceback" not in captured.err + captured.out
    return lines[0]


# --- YAML aliases --------------------------------------------------------------------


def test_the_loader_refuses_a_billion_laughs_before_building_anything() -> None:
    started = time.process_time()
    with pytest.raises(AliasError, match=f"more than {ALIAS_NODES} nodes"):
        safe_load(LAUGHS)
    assert time.process_time() - started < 5.0  # not a timing target: it must not expand


def test_the_loader_refuses_an_alias_inside_its_own_anchor() -> None:
    with pytest.raises(AliasError, match="refers to a node that contains it"):
        safe_load("a: &a [1, *a]\n")


def test_the_loader_reads_honest_aliases_and_big_files_as_safe_load_does(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(inputs, "ALIAS_NODES", 100)
    text = ("base: &base {speed: 0.5, radius: 0.2}\n"
            "robots: [*base, *base, *base]\n"
            f"long: {list(range(1000))}\n")  # ten times the bound, but nothing expanded
    assert safe_load(text) == yaml.safe_load(text)


def test_aliases_may_add_up_to_the_bound(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(inputs, "ALIAS_NODES", 100)
    below = f"a: &a {[0] * 90}\nb: [*a]\n"  # the alias adds 91 nodes
    assert safe_load(below)["b"][0] == [0] * 90
    above = f"a: &a {[0] * 60}\nb: [*a, *a]\n"  # 122
    with pytest.raises(AliasError, match="more than 100 nodes"):
        safe_load(above)


@pytest.mark.parametrize("how", ["--scenario", "--params"])
def test_params_refuses_a_billion_laughs_file(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                              how: str) -> None:
    path = tmp_path / "laughs.yaml"
    path.write_text(LAUGHS)
    assert zenav_main(["params", "planner", how, str(path)]) == 2
    assert one_line(capsys) == (f"zenav params: {path}: aliases expand to more than "
                                f"{ALIAS_NODES} nodes beyond those written; refused")


def test_run_refuses_a_billion_laughs_scenario_and_creates_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "laughs.yaml"
    path.write_text(LAUGHS)
    assert zenav_main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "aliases expand" in one_line(capsys)
    assert not (tmp_path / "o").exists()


def test_the_simulator_service_refuses_a_billion_laughs_scenario(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "laughs.yaml"
    path.write_text(LAUGHS)
    assert service_main("simulator", ["--set", f"scenario={path}"]) == 2
    assert one_line(capsys).startswith(f"zenav service simulator: {path}: aliases expand")


def test_a_set_value_with_runaway_aliases_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    laughs = "cruise_speed=" + "[" + ", ".join(
        ["&a0 [x, x, x, x, x, x, x, x, x]"]
        + [f"&a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]) + "]"
    assert zenav_main(["params", "planner", "--set", laughs]) == 2
    assert "aliases expand" in one_line(capsys)


# --- values quoted short -------------------------------------------------------------


def test_shown_cuts_a_long_value_to_80_characters() -> None:
    assert shown(1.5) == "1.5"
    assert shown("abc") == "'abc'"
    long = shown(list(range(100_000)))
    assert len(long) <= 80
    assert long.startswith("[0, 1, 2")
    assert len(shown("x" * 500)) <= 80
    assert len(shown({"k": [[["deep"] * 50] * 50] * 50})) <= 80


def test_a_huge_value_in_a_parameter_file_is_quoted_short(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "planner.yaml"
    path.write_text(yaml.safe_dump({"cruise_speed": list(range(5000))},
                                   default_flow_style=True))
    assert zenav_main(["params", "planner", "--params", str(path)]) == 2
    line = one_line(capsys)
    assert line.startswith(f"zenav params: {path}: cruise_speed: Input should be a valid "
                           "number (got [0, 1, 2")
    assert len(line) < len(str(path)) + 150


def test_a_huge_value_in_a_scenario_is_quoted_short(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario_with(tmp_path, "big", robot__speed=list(range(5000)))
    assert zenav_main(["params", "planner", "--scenario", str(path)]) == 2
    line = one_line(capsys)
    assert line.startswith(f"zenav params: {path}: robot.speed: must be a number (got [0, 1")
    assert len(line) < len(str(path)) + 150


def test_a_huge_set_is_quoted_short(capsys: pytest.CaptureFixture[str]) -> None:
    value = str(list(range(20_000)))
    assert zenav_main(["params", "planner", "--set", f"cruise_speed={value}"]) == 2
    line = one_line(capsys)
    assert line.startswith("zenav params: --set cruise_speed=[0, 1, 2")
    assert len(line) < 300


# --- paths ---------------------------------------------------------------------------


EMPTY_OUT = [["run", str(SCENARIO), "--out", ""], ["schemas", "--out", ""],
             ["paper", "--quick", "--out", ""], ["bench", "nav", "--out", ""],
             ["bench", "crowd", "--out", ""], ["bench", "bound", "--out", ""]]


@pytest.mark.parametrize("argv", EMPTY_OUT, ids=[" ".join(a[:2]) for a in EMPTY_OUT])
def test_an_empty_out_path_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      monkeypatch: pytest.MonkeyPatch, argv: list[str]) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        zenav_main(argv)
    assert exit_.value.code == 2
    command = " ".join(argv[:2]) if argv[0] == "bench" else argv[0]
    assert one_line(capsys) == f"zenav {command}: argument --out: the path is empty"
    assert list(tmp_path.iterdir()) == []


def test_run_with_a_refused_input_creates_no_out_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario_with(tmp_path, "neg", robot__radius=-0.2)
    out = tmp_path / "deep" / "out"
    assert zenav_main(["run", str(path), "--out", str(out)]) == 2
    assert one_line(capsys) == f"zenav run: {path}: robot.radius: must be > 0 (got -0.2)"
    assert not (tmp_path / "deep").exists()
    assert zenav_main(["run", str(SCENARIO), "--out", str(out), "--set", "planner.x=1"]) == 2
    assert not (tmp_path / "deep").exists()


# --- log levels ----------------------------------------------------------------------


@pytest.mark.parametrize("argv", [
    ["run", str(SCENARIO), "--out", "{t}/o", "--log-level", "NOPE"],
    ["run", str(SCENARIO), "--out", "{t}/o", "--engine", "inprocess", "--log-level", "NOPE"],
    ["router", "--log-level", "NOPE"],
], ids=["run", "run-inprocess", "router"])
def test_an_unknown_log_level_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               argv: list[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main([arg.format(t=tmp_path) for arg in argv])
    assert exit_.value.code == 2
    assert one_line(capsys) == (f"zenav {argv[0]}: argument --log-level: invalid choice: "
                                "'NOPE' (choose from 'DEBUG', 'INFO', 'WARNING', 'ERROR', "
                                "'CRITICAL')")
    assert not (tmp_path / "o").exists()


def test_a_service_refuses_an_unknown_log_level(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main(["service", "planner", "--log-level", "nope"])
    assert exit_.value.code == 2
    assert one_line(capsys).startswith("zenav service planner: argument --log-level: "
                                       "invalid choice: 'NOPE'")


def test_log_levels_are_read_in_any_case() -> None:
    args = build_light_parser("run").parse_args(["run", "s.yaml", "--out", "o",
                                                 "--log-level", "warning"])
    assert args.log_level == "WARNING"


# --- a service's own input -----------------------------------------------------------


@pytest.mark.parametrize(("name", "argv", "line"), [
    ("simulator", [],
     "zenav service simulator: the simulator needs a scenario: --set scenario=FILE"),
    ("simulator", ["--set", "scenario={t}/neg.yaml"],
     "zenav service simulator: {t}/neg.yaml: robot.radius: must be > 0 (got -0.2)"),
    ("simulator", ["--set", "scenario={t}/none.yaml"],
     "zenav service simulator: {t}/none.yaml: file not found"),
    ("planner", ["--standby-lock", "/proc/zenav/x/lock"],
     "zenav service planner: --standby-lock /proc/zenav/x/lock: under /proc, which is not a place "
     "for output"),
    ("planner", ["--standby-lock", "{t}/neg.yaml/lock"],
     "zenav service planner: --standby-lock {t}/neg.yaml/lock: {t}/neg.yaml is a file, not a "
     "folder"),
    ("planner", ["--standby-lock", "{t}"],
     "zenav service planner: --standby-lock {t}: is a folder, not a file"),
], ids=["no-scenario", "bad-scenario", "missing-scenario", "standby-lock-in-proc",
        "standby-lock-under-a-file", "standby-lock-a-folder"])
def test_a_service_refuses_its_bad_input_with_one_line_and_status_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, argv: list[str],
        line: str) -> None:
    scenario_with(tmp_path, "neg", robot__radius=-0.2)
    code = zenav_main(["service", name, *(arg.format(t=tmp_path) for arg in argv)])
    assert code == 2
    assert one_line(capsys) == line.format(t=tmp_path)


@pytest.mark.parametrize("port", ["70000", "0", "65530", "x"])
def test_a_service_refuses_a_base_port_out_of_range(capsys: pytest.CaptureFixture[str],
                                                    port: str) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main(["service", "planner", "--base-port", port])
    assert exit_.value.code == 2
    assert one_line(capsys).startswith("zenav service planner: argument --base-port: ")


def test_service_name_help_is_the_services_own(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main(["service", "simulator", "--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: zenav service simulator")
    assert "--set NAME=VALUE" in out and "zenav params simulator" in out


def test_service_help_without_a_name_lists_the_services(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main(["service", "--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: zenav service") and "motor_bridge" in out


# --- the command's end ---------------------------------------------------------------


def test_nothing_is_imported_after_the_command_ends(tmp_path: Path) -> None:
    """``main`` asks the service runner and the tools whether to end the process at once
    only if the command loaded them: an import after the command's own SIGINT handling
    was where a late Ctrl-C became a traceback."""
    modules = loaded_by("from zenav.cli import main\n"
                        f"assert main(['schemas', '--out', {str(tmp_path / 's')!r}]) == 0")
    assert "zenav.tooling" not in modules


# --- numbers that are not finite ------------------------------------------------------


@pytest.mark.parametrize(("value", "got"), [("inf", "inf"), ("1e400", "inf"), (".inf", "inf"),
                                            ("-.inf", "-inf"), ("nan", "'nan'")])
def test_params_refuses_a_non_finite_number(capsys: pytest.CaptureFixture[str], value: str,
                                            got: str) -> None:
    assert zenav_main(["params", "planner", "--set", f"cruise_speed={value}"]) == 2
    assert one_line(capsys) == (f"zenav params: --set cruise_speed={value}: cruise_speed: "
                                f"must be a finite number (got {got})")


@pytest.mark.parametrize("assignment", ["perception.lambda_=1e400", "perception.lambda_=inf",
                                        "planner.cruise_speed=inf", "planner.cruise_speed=nan"])
def test_run_refuses_a_non_finite_number(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         assignment: str) -> None:
    out = tmp_path / "o"
    assert zenav_main(["run", str(SCENARIO), "--out", str(out), "--set", assignment]) == 2
    assert one_line(capsys).endswith("must be a finite number (got "
                                     f"{'inf' if 'nan' not in assignment else repr('nan')})")
    assert not out.exists()


def test_a_parameter_file_with_inf_is_refused(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "perception.yaml"
    path.write_text("lambda_: .inf\n")
    assert service_main("perception", ["--config", str(path)]) == 2
    assert one_line(capsys) == (f"zenav service perception: {path}: lambda_: must be a finite "
                                "number (got inf)")


# --- the benchmarks' numbers ---------------------------------------------------------

BAD_NUMBERS = [
    (["bench", "perf", "--obstacles", "-1"], "zenav bench perf: argument --obstacles: must be "
     ">= 0 (got -1)"),
    (["bench", "perf", "--rates", "abc"], "zenav bench perf: argument --rates: expected a "
     "number (got 'abc')"),
    (["bench", "perf", "--rates", "10,0"], "zenav bench perf: argument --rates: must be > 0 "
     "(got 0)"),
    (["bench", "perf", "--scans", "0"], "zenav bench perf: argument --scans: must be >= 1 "
     "(got 0)"),
    (["bench", "perf", "--latency-seconds", "-1"], "zenav bench perf: argument "
     "--latency-seconds: must be > 0 (got -1)"),
    (["bench", "perf", "--rate-seconds", "0"], "zenav bench perf: argument --rate-seconds: "
     "must be > 0 (got 0)"),
    (["bench", "accuracy", "--duration", "nan"], "zenav bench accuracy: argument --duration: "
     "must be a finite number (got nan)"),
    (["bench", "accuracy", "--seeds", "0"], "zenav bench accuracy: argument --seeds: must be "
     ">= 1 (got 0)"),
    (["soak", "--minutes", "-1"], "zenav soak: argument --minutes: must be > 0 (got -1)"),
    (["soak", "--minutes", "0"], "zenav soak: argument --minutes: must be > 0 (got 0)"),
    (["soak", "--rate-hz", "1e9"], "zenav soak: argument --rate-hz: must be > 0 and <= 10000 "
     "(got 1e9)"),
    (["soak", "--rate-hz", "nan"], "zenav soak: argument --rate-hz: must be a finite number "
     "(got nan)"),
    (["soak", "--warmup", "-1"], "zenav soak: argument --warmup: must be >= 0 (got -1)"),
    (["soak", "--window", "0"], "zenav soak: argument --window: must be > 0 (got 0)"),
    (["soak", "--max-growth", "nan"], "zenav soak: argument --max-growth: must be a finite "
     "number (got nan)"),
    (["bench", "nav", "--seed", "-1"], "zenav bench nav: argument --seed: must be >= 0 "
     "(got -1)"),
    (["bench", "crowd", "--seed", "-1"], "zenav bench crowd: argument --seed: must be >= 0 "
     "(got -1)"),
]


@pytest.mark.parametrize(("argv", "line"), BAD_NUMBERS, ids=[" ".join(a) for a, _ in BAD_NUMBERS])
def test_a_benchmarks_bad_number_names_its_option(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], line: str) -> None:
    with pytest.raises(SystemExit) as exit_:
        zenav_main([*argv, "--out", str(tmp_path / "o")] if argv[1] != "accuracy" else argv)
    assert exit_.value.code == 2
    assert one_line(capsys) == line
    assert not (tmp_path / "o").exists()


def test_the_benchmarks_defaults_pass_their_own_checks() -> None:
    from zenav.cli import build_parser

    perf = build_parser().parse_args(["bench", "perf"])
    assert perf.obstacles == (0, 5, 20) and perf.rates == (10, 50, 100, 200, 300, 400, 600)
    soak = build_parser().parse_args(["soak"])
    assert (soak.minutes, soak.rate_hz, soak.warmup, soak.window) == (30.0, 100.0, 30.0, 60.0)


def test_version_and_every_subcommand_says_what_it_is_for(
        capsys: pytest.CaptureFixture[str]) -> None:
    from importlib.metadata import version

    from zenav.cli import build_parser

    with pytest.raises(SystemExit) as exit_:
        zenav_main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out.strip() == f"zenav {version('zenav')}"
    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    bench = commands.choices["bench"]
    kinds = next(a for a in bench._actions if isinstance(a, argparse._SubParsersAction))
    undescribed = [name for name, child in [*commands.choices.items(), *kinds.choices.items()]
                   if not child.description]
    assert undescribed == []


def _options(parser: argparse.ArgumentParser, name: str) -> list[tuple[str, argparse.Action]]:
    found: list[tuple[str, argparse.Action]] = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for word, child in action.choices.items():
                found += _options(child, f"{name} {word}")
        elif not isinstance(action, argparse._HelpAction | argparse._VersionAction):
            found.append((f"{name} {'/'.join(action.option_strings) or action.dest}", action))
    return found


def test_every_option_of_every_command_has_help_that_gives_its_default() -> None:
    """``zenav CMD --help`` explains each option, and a value used when the option is
    left out is written in its help (argparse does not show it by itself)."""
    silent, undisclosed = [], []
    for where, action in _options(build_parser(), "zenav"):
        if not action.help:
            silent.append(where)
        elif (action.default not in (None, False, [], argparse.SUPPRESS)
              and not isinstance(action, argparse._StoreTrueAction)
              and "default" not in action.help):
            undisclosed.append(f"{where} ({action.default!r})")
    assert silent == [], "options without help"
    assert undisclosed == [], "defaults not in the help"
