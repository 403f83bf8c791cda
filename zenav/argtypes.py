"""Argument types for argparse shared by the commands: each turns the text into the value
or raises ``argparse.ArgumentTypeError`` with what is wrong, so a bad number or path is
one line naming the option (``zenav soak: argument --minutes: must be > 0 (got -1)``),
status 2, before any work starts."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

__all__ = ["count", "float_at_least", "floats", "ints", "non_negative_float",
           "non_negative_int", "nonempty", "path", "port", "positive_float",
           "positive_float_at_most", "positive_int"]

T = TypeVar("T")


def path(text: str) -> Path:
    """A file or folder path; refused when empty (``--out ""`` would be the current
    folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("the path is empty")
    return Path(text)


def _float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number (got {text!r})") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number (got {text})")
    return value


def _int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number (got {text!r})") from None


def positive_float(text: str) -> float:
    """A finite number > 0."""
    value = _float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0 (got {text})")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    value = _float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0 (got {text})")
    return value


def positive_int(text: str) -> int:
    """A whole number >= 1."""
    value = _int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1 (got {text})")
    return value


def non_negative_int(text: str) -> int:
    """A whole number >= 0."""
    value = _int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0 (got {text})")
    return value


def positive_float_at_most(high: float) -> Callable[[str], float]:
    """A finite number in (0, high]."""

    def parse(text: str) -> float:
        value = _float(text)
        if not 0 < value <= high:
            raise argparse.ArgumentTypeError(f"must be > 0 and <= {high:g} (got {text})")
        return value

    return parse


def count(low: int, high: int) -> Callable[[str], int]:
    """A whole number in [low, high]."""

    def parse(text: str) -> int:
        value = _int(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be in {low}..{high} (got {text})")
        return value

    return parse


def floats(item: Callable[[str], float]) -> Callable[[str], tuple[float, ...]]:
    """A comma-separated list of at least one number, each checked by ``item``."""
    return _listed(item, "numbers")


def ints(item: Callable[[str], int]) -> Callable[[str], tuple[int, ...]]:
    """A comma-separated list of at least one whole number, each checked by ``item``."""
    return _listed(item, "whole numbers")


def _listed(item: Callable[[str], T], what: str) -> Callable[[str], tuple[T, ...]]:
    def parse(text: str) -> tuple[T, ...]:
        parts = [part.strip() for part in text.split(",") if part.strip()]
        if not parts:
            raise argparse.ArgumentTypeError(f"expected {what} separated by commas "
                                             f"(got {text!r})")
        return tuple(item(part) for part in parts)

    return parse


def float_at_least(low: float) -> Callable[[str], float]:
    """A finite number >= ``low``."""

    def parse(text: str) -> float:
        value = _float(text)
        if value < low:
            raise argparse.ArgumentTypeError(f"must be >= {low:g} (got {text})")
        return value

    return parse


port = count(0, 65535)
"""A TCP or UDP port."""


def nonempty(text: str) -> str:
    """A string with more than blanks in it."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty")
    return text

