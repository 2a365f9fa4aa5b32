"""Every number ``reports/README.md`` quotes is true of what it describes.

Each claim below is a phrase of the README with its numbers left open, and the
place the numbers come from: the baseline scenario and its path, the figures'
own runs (the seven simulations of Fig. 22-30), the committed
``reports/table_7_1/table_7_1.csv`` (the thesis's published column) and, for the thesis's
example lag, ``docs/sources.md``.  A number must equal its source rounded to the
digits printed.  Every number in the README's prose must belong to a claim or
be a reference (Fig. 8, §4.2, eq. 6.2, step 6.2, Table 7.1): a number added to
the README without a check fails the last test.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cell.reporting.published import TABLE_7_1_CYCLES
from tests import readme_claims_path  # noqa: F401 - registers its claims
from tests.readme_claims_cycles import _cycle_claims
from tests.readme_sources import CLAIMS, README, Check, Sources, agrees, prose, value


@pytest.fixture(scope="module")
def src() -> Sources:
    return Sources()


# --------------------------------------------------------------------------- the tests
#: Numbers that are references, not quantities: figures, sections, equations, steps, tables.
REFERENCES = [r"3-D", r"Fig\. \d+(?:–\d+)?", r"§\d+(?:\.\d+)*(?:–\d+(?:\.\d+)*)?", r"[Ee]q\. \d+\.\d+",
              r"step \d+\.\d+", r"Table \d+\.\d+", r"King \(1984\)"]


def matches() -> list[tuple[re.Match[str], Check]]:
    text = prose(README.read_text())
    return [(m, check) for pattern, check in CLAIMS for m in pattern.finditer(text)]


def test_every_claim_is_found_in_the_readme() -> None:
    text = prose(README.read_text())
    missing = [p.pattern for p, _ in CLAIMS if not p.search(text)]
    assert missing == []
    cycles = [value(m[1]) for m, check in matches() if check is _cycle_claims]
    assert sorted(cycles) == sorted(TABLE_7_1_CYCLES[1:])   # Fig. 26-30, one each


def test_every_number_quoted_is_its_source_rounded(src: Sources) -> None:
    wrong = []
    for m, check in matches():
        for printed, expected, *tol in check(src, list(m.groups())):
            if not agrees(printed, float(expected), *tol):
                wrong.append(f"{printed} (should read {float(expected):.6g}) in: {m[0][:90]}")
    assert wrong == []


def test_every_number_in_the_readme_is_checked() -> None:
    text = prose(README.read_text())
    checked = [range(*m.span(g)) for m, _ in matches() for g in range(1, len(m.groups()) + 1)]
    references = [range(*r.span()) for pattern in REFERENCES for r in re.finditer(pattern, text)]

    def covered(span: tuple[int, int]) -> bool:
        return any(span[0] in r for r in checked) or any(span[0] in r for r in references)

    loose = [text[max(n.start() - 40, 0):n.end() + 10] for n in
             re.finditer(r"(?<![\w.])[−+-]?\d+(?:\.\d+)?", text) if not covered(n.span())]
    assert loose == []


def anchors(doc: Path) -> set[str]:
    """GitHub's anchors of a page's headings: lower case, punctuation dropped, spaces to '-'."""
    heads = [line.lstrip("#").strip().lower() for line in doc.read_text().splitlines()
             if line.startswith("#")]
    return {"".join(c for c in h if c.isalnum() or c in " -_").replace(" ", "-") for h in heads}


def test_links_point_at_pages_and_sections_that_exist() -> None:
    links = re.findall(r"\]\((\.\./docs/[\w.-]+\.md)(?:#([\w-]+))?\)", README.read_text())
    assert len(links) >= 8
    for page, anchor in links:
        path = (README.parent / page).resolve()
        assert path.exists(), page
        if anchor:
            assert anchor in anchors(path), (page, anchor)
    for word in ("SPEC", "shared/"):
        assert word not in README.read_text()
    assert not re.search(r"issue|#\d", prose(README.read_text()), re.IGNORECASE)
