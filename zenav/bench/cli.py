"""``zenav bench perf|nav|crowd|bound|accuracy`` and ``zenav soak``: the benchmarks'
commands (results in ``docs/benchmarks.md``)."""

from __future__ import annotations

from typing import Any

from zenav.bench import bound, crowd, nav, perf, soak, tracking_accuracy


def add_commands(sub: Any) -> None:
    """Add ``bench`` (with its kinds) and ``soak`` to the ``zenav`` parser's subcommands."""
    bench = sub.add_parser("bench", help="benchmarks: compute and transport, navigation")
    kinds = bench.add_subparsers(dest="bench", required=True)
    perf.add_command(kinds)
    nav.add_command(kinds)
    crowd.add_command(kinds)
    bound.add_command(kinds)
    tracking_accuracy.add_command(kinds)
    soak.add_command(sub)
