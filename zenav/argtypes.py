"""Argument types the commands share: a bad value is refused by argparse, before anything
starts, with the option's name and what it must be (exit status 2)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import NoReturn


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def positive_float(text: str) -> float:
    """A finite number above 0 (a duration, a period, a rate, a timeout)."""
    value = _number(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number above 0, not {text}")
    return value


def float_at_least(low: float) -> Callable[[str], float]:
    """A finite number of at least ``low``."""

    def check(text: str) -> float:
        value = _number(text)
        if not (math.isfinite(value) and value >= low):
            raise argparse.ArgumentTypeError(f"must be a finite number of at least {low:g}, "
                                             f"not {text}")
        return value

    return check


def int_between(low: int, high: int) -> Callable[[str], int]:
    """A whole number from ``low`` to ``high``, both included."""

    def check(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be from {low} to {high}, not {value}")
        return value

    return check


port = int_between(0, 65535)
"""A TCP or UDP port."""


def nonempty(text: str) -> str:
    """A string with something in it but blanks."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty")
    return text


def one_line_errors(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """``parser``, whose refusals are one line ``PROG: --option: problem`` and exit status
    2, without the usage summary argparse prints before them (``--help`` still shows it)."""

    def error(message: str) -> NoReturn:
        parser.exit(2, f"{parser.prog}: {message.removeprefix('argument ')}\n")

    parser.error = error  # type: ignore[method-assign]
    return parser
