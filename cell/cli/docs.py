"""``cell docs [PAGE] [--path]``: the model's documentation, shipped with the package.

The pages of ``docs/`` (the model, the two accountings, the corrections to the
sources, the assumed values, a glossary) are installed inside the package, so a
user who installed ``cell`` with pip reads what its output refers to
(``docs/accounting.md`` is ``cell docs accounting``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = "read the documentation: the model, the accountings, the sources, the assumptions"
DESCRIPTION = ("The pages of docs/, as installed with the package: without PAGE a list, with "
               "PAGE the page's text (Markdown).")

#: Where the pages are: inside the package (in the repository, a link to docs/).
PAGES = Path(__file__).resolve().parent.parent / "docs"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("page", nargs="?", default=None,
                   help="a page, e.g. accounting or docs/accounting.md (default: list them)")
    p.add_argument("--path", action="store_true", help="print where the page is, not its text")


def pages() -> dict[str, Path]:
    """Every page by name (the file's stem), README first."""
    found = sorted(PAGES.glob("*.md"), key=lambda f: (f.stem != "README", f.stem))
    return {f.stem: f for f in found}


def title(page: Path) -> str:
    """The page's first heading."""
    for line in page.read_text(encoding="utf-8").splitlines():
        if line.startswith("# "):
            return line[2:].strip()
    return page.stem


def main(args: argparse.Namespace) -> int:
    from cell.plumbing.errors import CellError

    known = pages()
    if args.page is None:
        width = max(len(name) for name in known)
        for name, listed in known.items():
            print(f"  {name:<{width}}  {title(listed)}" + (f"  ({listed})" if args.path else ""))
        print("cell docs PAGE prints a page (Markdown); pipe it to a pager: cell docs model | less")
        return 0
    name = Path(args.page).name.lower().removesuffix(".md")
    page = {stem.lower(): path for stem, path in known.items()}.get(name)
    if page is None:
        raise CellError(f"no documentation page {args.page!r} (pages: {', '.join(known)})")
    if args.path:
        print(page)
    else:
        print(page.read_text(encoding="utf-8"), end="")
    return 0
