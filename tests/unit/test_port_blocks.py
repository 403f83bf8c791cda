"""Stacks started at the same moment on one machine get blocks of loopback ports that do
not overlap: a block is reserved (a lock per port) from the moment it is chosen until the
stack stops or its process ends, not merely checked free. Without the reservation two
``zenav run`` started together could pick overlapping blocks, and one of them failed
with "address already in use" when its services bound their ports a second later."""

from __future__ import annotations

import subprocess
import sys

from zenav.launch import _held, _lock_ports, _unlock, free_port_block, release_port_block

BLOCK = 7
RESERVE_AND_WAIT = (
    "import sys\n"
    "from zenav.launch import free_port_block\n"
    "print(' '.join(str(free_port_block({block})) for _ in range({count})), flush=True)\n"
    "sys.stdin.read()\n"
)


def ports(bases: list[int]) -> list[int]:
    return [port for base in bases for port in range(base, base + BLOCK)]


def test_blocks_reserved_in_one_process_never_overlap() -> None:
    # 300 random blocks of 7 among 12000 ports would overlap some twenty times over.
    bases = [free_port_block(BLOCK) for _ in range(300)]
    try:
        assert len(set(ports(bases))) == len(ports(bases))
    finally:
        for base in bases:
            release_port_block(base)
    assert not set(bases) & set(_held)


def test_blocks_reserved_by_two_processes_at_once_never_overlap() -> None:
    script = RESERVE_AND_WAIT.format(block=BLOCK, count=150)
    procs = [subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True) for _ in range(2)]
    try:
        chosen = [[int(base) for base in proc.stdout.readline().split()]  # type: ignore[union-attr]
                  for proc in procs]
    finally:
        for proc in procs:
            proc.communicate(timeout=30)  # closes stdin: the process ends, its locks go
    assert [len(bases) for bases in chosen] == [150, 150]
    assert not set(ports(chosen[0])) & set(ports(chosen[1]))


def test_a_block_held_by_a_process_is_free_again_when_the_process_ends() -> None:
    script = RESERVE_AND_WAIT.format(block=BLOCK, count=1)
    proc = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    try:
        base = int(proc.stdout.readline())  # type: ignore[union-attr]
        assert _lock_ports(range(base, base + BLOCK)) is None  # held there: not chosen here
    finally:
        proc.communicate(timeout=30)
    locks = _lock_ports(range(base, base + BLOCK))
    assert locks  # the process is gone, and so are its locks
    _unlock(locks)


def test_a_released_block_can_be_locked_again() -> None:
    base = free_port_block(BLOCK)
    assert _lock_ports(range(base, base + BLOCK)) is None
    release_port_block(base)
    locks = _lock_ports(range(base, base + BLOCK))
    assert locks
    _unlock(locks)
