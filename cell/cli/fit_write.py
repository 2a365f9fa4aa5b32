"""``cell fit``'s output: the figure and the block written together (or the block printed),
then the table of fits (:func:`write`); what they hold is made by
:mod:`cell.experiments.fit.block`."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from cell.experiments.fit.block import Result
from cell.experiments.fit.fitted_data import Data


def write(args: argparse.Namespace, data: Data, result: Result, out: Path | None,
          figure: Path | None) -> None:
    """Write the figure and the block together (or print the block), then print the table."""
    from cell.plumbing.output.atomic import atomic_paths

    targets = [t for t in (figure, out) if t is not None]
    with atomic_paths(*targets) as tmps:  # both written in full, then put in place together
        staged = dict(zip(targets, tmps))
        if figure is not None:
            _draw(args, data, result, staged[figure])
        if out is not None:
            staged[out].write_text(result.block, encoding="utf-8")
    comment = "# " if out is None else ""  # printed table and block together are valid YAML
    print("\n".join(comment + line for line in result.table.splitlines()))
    print(result.block.rstrip("\n") if out is None else f"wrote {out}")
    if figure is not None:
        print(f"{comment}wrote {figure}")


def _draw(args: argparse.Namespace, data: Data, result: Result, path: Any) -> None:
    from cell.experiments.fit.figure import draw, draw_censored

    what = {"time_to_failure": "time to failure", "time_to_repair": "time to repair"}.get(args.block)
    if data.censored is not None:
        draw_censored(data.values, data.censored, result.fits, path, best=result.chosen,
                      xlabel=f"{what}, column {args.column} (s)")
        return
    label = (f"{what}, column {args.column} (s)" if what else
             f"gap between the arrival times in {args.column} (s)" if args.times else
             f"inter-arrival time, column {args.column} (s)")
    draw(data.values, result.fits, path, best=result.chosen, xlabel=label)
