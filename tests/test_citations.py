"""Everything the code, tests, README and CLI cite lives in the repository."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = [*ROOT.glob("impactqp/**/*.py"), *ROOT.glob("benchmarks/*.py"), ROOT / "README.md",
           ROOT / ".ci" / "run",
           *(p for p in ROOT.glob("tests/*.py") if p.name != "test_citations.py")]
THEORY = ROOT / "docs" / "theory.md"


def sections() -> set[int]:
    return {int(n) for n in re.findall(r"^## (\d+)\. ", THEORY.read_text(encoding="utf-8"),
                                      flags=re.M)}


def test_every_section_citation_names_the_theory_note() -> None:
    group = re.compile(r"docs/theory\.md\s+§\d+(?:\s*(?:,|–|and)\s*(?:#\s*)?§\d+)*")
    bad = []
    for path in SOURCES:
        text = group.sub("", path.read_text(encoding="utf-8"))
        bad += [f"{path.relative_to(ROOT)}: …{text[max(0, i - 60):i + 5]!r}"
                for i in [m.start() for m in re.finditer("§", text)]]
    assert bad == []


def test_cited_sections_exist() -> None:
    have = sections()
    assert set(range(1, 13)) <= have
    cited = {int(n) for path in SOURCES
             for n in re.findall(r"docs/theory\.md §(\d+)", path.read_text(encoding="utf-8"))}
    assert cited and cited <= have


def test_no_document_outside_the_repository_is_named() -> None:
    for path in SOURCES:
        text = path.read_text(encoding="utf-8")
        for name in ("impact-" + "geometry", "../" + "shared", "shared/" + "peer-data"):
            assert name not in text, (path, name)
