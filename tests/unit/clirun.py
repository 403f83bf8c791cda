"""The ``zenav`` command run in this process, as the tests of its input use it."""

from __future__ import annotations

import pytest

from zenav.cli import main as zenav_main


def status_of(argv: list[str]) -> int:
    """The exit status of ``zenav argv``, argparse's refusals (which exit) included."""
    try:
        return zenav_main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)


def zenav(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    """(exit status, stderr lines) of ``zenav argv``."""
    code = status_of(argv)
    return code, capsys.readouterr().err.splitlines()
