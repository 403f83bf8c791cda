"""Compiled inner loops: the one place the services turn to numba.

A few hot loops of the pipeline (a ray per beam over the map, a roll-out per candidate
over the horizon) are sequential in a way numpy cannot express without a pass over
whole arrays for every step. :func:`kernel` compiles such a loop with numba (``njit``,
in ``nopython`` mode, cached on disk next to the module, so a process that starts later
loads the machine code instead of compiling it again).

The loops stay plain, typed Python: ``NUMBA_DISABLE_JIT=1`` runs them as written, for a
debugger or a profiler, with the same results. The kernels use no ``fastmath``, so their
floating-point arithmetic is the same as the numpy it replaced, operation for
operation.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba

F = TypeVar("F", bound=Callable[..., Any])


def kernel(function: F) -> F:
    """``function`` compiled to machine code on its first call (or loaded from the
    on-disk cache), with the same signature."""
    return cast(F, numba.njit(cache=True, nogil=True)(function))
