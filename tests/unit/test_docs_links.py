"""Every relative link and image in the README and under docs/ points at a file that is
in the repository (a report once linked animations that were never committed)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: str(p.relative_to(REPO)))
def test_relative_links_point_at_committed_files(document: Path) -> None:
    targets = [t for t in LINK.findall(document.read_text())
               if not t.startswith(("http://", "https://", "mailto:", "#"))]
    missing = [t for t in targets if not (document.parent / t.split("#")[0]).exists()]
    assert missing == [], f"{document.name} links missing files: {missing}"
