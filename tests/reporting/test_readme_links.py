"""The README, reports/README.md and docs/usage.md point at each other: every link and anchor resolves,
in the repository and as ``cell docs`` ships the page, and each reference section has a pointer."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LINK = re.compile(r"\]\(([^)#\s]+)(?:#([^)\s]*))?\)")


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    return {slug(m) for m in re.findall(r"^#+ (.*)$", text, re.M)}


def links(page: Path) -> list[tuple[str, str]]:
    return [(target, anchor) for target, anchor in LINK.findall(page.read_text(encoding="utf-8"))
            if not target.startswith("http")]


@pytest.mark.parametrize("page", ["README.md", "docs/usage.md", "reports/README.md"])
def test_every_link_and_anchor_resolves_in_the_repository(page):
    source = ROOT / page
    for target, anchor in links(source):
        path = (source.parent / target).resolve()
        assert path.exists(), f"{page}: {target}"
        if anchor and path.suffix == ".md":
            assert anchor in anchors(path), f"{page}: {target}#{anchor}"


def test_usage_links_work_as_cell_docs_ships_the_page():
    """Installed, docs/ is cell/docs/: ``../X`` is the package's X. Only the README is left
    behind, and the page says where it is (and what to use instead)."""
    usage = ROOT / "docs" / "usage.md"
    outside = []
    for target, _ in links(usage):
        if target.startswith("../"):
            if not (ROOT / "cell" / target[3:]).is_file():
                outside.append(target)
        else:
            assert (ROOT / "cell" / "docs" / target).is_file(), target
    assert outside == ["../README.md"] * len(outside) and outside


def test_the_readme_points_at_every_reference_section():
    usage = ROOT / "docs" / "usage.md"
    pointed = {anchor for target, anchor in links(ROOT / "README.md") if target == "docs/usage.md"}
    sections = {slug(h) for h in re.findall(r"^## (.*)$", usage.read_text(encoding="utf-8"), re.M)}
    assert sections and sections <= pointed
