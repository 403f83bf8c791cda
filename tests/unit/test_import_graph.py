"""The import graph between the top-level packages, read from the source with ``ast``.

schemas/ -> nothing of ours; services/ -> schemas; sim/ -> schemas and services; the outer
zenav/ may import them all. Every import is ``zenav.``-prefixed (schemas/, services/ and
sim/ are installed as zenav.schemas, zenav.services and zenav.sim).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = {"schemas": "zenav.schemas", "services": "zenav.services", "sim": "zenav.sim",
           "zenav": "zenav"}
INNER = ("zenav.schemas", "zenav.services", "zenav.sim")
ALLOWED = {
    "zenav.schemas": set(),
    "zenav.services": {"zenav.schemas"},
    "zenav.sim": {"zenav.schemas", "zenav.services"},
}


def top_package(module: str) -> str | None:
    """zenav.schemas / zenav.services / zenav.sim / zenav for one of ours, else None."""
    for inner in INNER:
        if module == inner or module.startswith(inner + "."):
            return inner
    if module == "zenav" or module.startswith("zenav."):
        return "zenav"
    return None


def imported_modules(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}:{node.lineno}: relative import (write zenav.…)"
            assert node.module is not None
            names.append(node.module)
            names.extend(f"{node.module}.{alias.name}" for alias in node.names
                         if node.module == "zenav")
    return names


def sources() -> dict[Path, str]:
    files = {}
    for folder, package in FOLDERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            files[path] = package
    return files


def package_graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {package: set() for package in FOLDERS.values()}
    for path, package in sources().items():
        for module in imported_modules(path):
            target = top_package(module)
            if target is not None and target != package:
                graph[package].add(target)
    return graph


def test_sources_are_found() -> None:
    packages = set(sources().values())
    assert packages == set(FOLDERS.values())


def test_no_bare_imports_of_the_top_level_folders() -> None:
    bare = [f"{path.relative_to(ROOT)}: {module}"
            for path in sources() for module in imported_modules(path)
            if module.split(".")[0] in ("schemas", "services", "sim")]
    assert bare == []


def test_each_inner_package_imports_only_what_it_may() -> None:
    graph = package_graph()
    for package, allowed in ALLOWED.items():
        assert graph[package] <= allowed, f"{package} imports {graph[package] - allowed}"


def test_no_cycle_between_top_level_packages() -> None:
    graph = package_graph()

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        for nxt in graph[start]:
            if nxt == goal or (nxt not in seen and reaches(nxt, goal, seen | {nxt})):
                return True
        return False

    cycles = [package for package in graph if reaches(package, package, {package})]
    assert cycles == []


def test_the_checks_catch_a_violation(tmp_path: Path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("import services.node\nfrom zenav.sim.kinematics import step_robot\n")
    assert imported_modules(bad) == ["services.node", "zenav.sim.kinematics"]
    assert top_package("zenav.sim.kinematics") == "zenav.sim"
    assert top_package("zenav.run") == "zenav"
    assert top_package("numpy") is None
