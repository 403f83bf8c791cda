"""The README's table of services, keys read and keys written, against what the services
declare (issue 14: the table once left out that the motor bridge reads ``scan``)."""

from __future__ import annotations

import re
from pathlib import Path

from zenav.graph import derive_graph

README = Path(__file__).resolve().parents[2] / "README.md"


def readme_service_table() -> dict[str, tuple[set[str], set[str]]]:
    """service -> (keys read, keys written) from the README's "| service | reads | writes |"
    table; a cell's keys are its `code` spans (remarks in brackets are left out)."""
    lines = README.read_text().splitlines()
    start = lines.index("| service | reads | writes |")
    table: dict[str, tuple[set[str], set[str]]] = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        service, reads, writes = (cell.strip() for cell in line.strip("|").split("|"))
        table[service] = (set(re.findall(r"`([^`]+)`", reads)),
                          set(re.findall(r"`([^`]+)`", writes)))
    return table


def test_the_readme_service_table_is_the_services_own_graph() -> None:
    graph = derive_graph()["services"]
    table = readme_service_table()
    assert set(table) == set(graph)
    for service, entry in graph.items():
        reads, writes = table[service]
        assert reads == set(entry.get("subscribes", {})), service
        assert writes == set(entry.get("publishes", {})), service
