"""reports/kn/: KN's probability of correct selection on count measures, measured
(``make kn-check``, i.e. ``python -m cell.reporting.kn_report reports/kn``).

Two cases, each over :data:`MACRO` independent problems with a known best, screened by
:func:`cell.experiments.kn_check.macro_pcs` with KN's first-stage rule and without it:

- **simulated**: parts missed by the fixed-cycle robot in runs of :data:`PARTS` parts at
  three cycles (mostly 0 at the shortest).  A pool of :data:`POOL` replications of the three
  points on common random numbers is simulated once; each problem draws its replications
  from the pool with replacement, so the pool's means are the true means and δ is the
  pool's gap between the best and the second: the best is better by exactly δ.  Drawn as
  whole rows (``CRN``: the points' counts move together, as a sweep's do), and each point
  from a row of its own (``independent``: counts that do not move together).
- **Poisson**: independent Poisson counts, 0.1 for the best and 0.35 for three others,
  δ = 0.25 (the slippage configuration: every other system exactly δ worse).

``pcs.csv`` has a row per case, first stage and rule; ``README.md`` the table and what it shows.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from cell.experiments.kn_check import MacroResult, macro_pcs, poisson_draw, pool_draw
from cell.plumbing.output.atomic import OutputDir
from cell.reporting.formatting import table_head, table_row

MACRO = 2000
PCS = 0.95
PARTS = 10
CYCLES = (20.1, 20.6, 21.0)
POOL = 4000
SEED = 1984
POISSON = (0.1, 0.35, 0.35, 0.35)
POISSON_DELTA = 0.25
FILES = ("pcs.csv", "README.md")
COLUMNS = ["case", "n0", "rule", "macro", "refused", "unfinished", "decided", "correct",
           "pcs", "se", "holds"]


def pool() -> np.ndarray:
    """Parts missed, (POOL, 3): replication r of each cycle on ``SeedSequence(SEED, (r,))``."""
    from cell.experiments.study import measures_of
    from cell.scenario import catalog
    from cell.scenario.schema import load_scenario
    from cell.sim.assembly import assemble
    from cell.sim.simulation import simulate

    base = load_scenario(catalog.resolve("baseline.yaml"))
    out = np.empty((POOL, len(CYCLES)))
    for j, cycle in enumerate(CYCLES):
        cell = assemble(base.with_overrides({"run.parts": PARTS, "controller.policy": "non-adaptive",
                                             "controller.ideal_cycle_s": cycle}))
        for r in range(POOL):
            row = simulate(cell, seed=np.random.SeedSequence(SEED, spawn_key=(r,)),
                           keep_parts=False, keep_belts=False).summary
            out[r, j] = measures_of(row.as_dict())["parts_missed"]
    return out


def simulated_delta(x: np.ndarray) -> float:
    """The pool's gap between its best (fewest missed) and its second point."""
    means = np.sort(x.mean(axis=0))
    return float(means[1] - means[0])


def poisson_rows(n0s: tuple[int, ...] = (3, 10, 20)) -> Iterator[dict]:
    for n0 in n0s:
        for rule in (True, False):
            draw = poisson_draw(list(POISSON), MACRO, seed=SEED + n0)
            yield _row("Poisson", n0, rule,
                       macro_pcs(draw, 0, POISSON_DELTA, n0, PCS, maximize=False, rule=rule))


def simulated_rows(x: np.ndarray) -> Iterator[dict]:
    delta, best = simulated_delta(x), int(np.argmin(x.mean(axis=0)))
    for common in (True, False):
        for n0 in (2, 3, 5, 10):
            for rule in (True, False):
                draw = pool_draw(x, MACRO, seed=SEED + n0, common=common)
                yield _row(f"simulated, {'CRN' if common else 'independent'}", n0, rule,
                           macro_pcs(draw, best, delta, n0, PCS, maximize=False, rule=rule))


def holds(pcs: float, se: float) -> bool:
    """The check: at or above the nominal PCS minus its own standard error."""
    return bool(pcs >= PCS - se)


def _row(case: str, n0: int, rule: bool, m: MacroResult) -> dict:
    return {"case": case, "n0": n0, "rule": "with" if rule else "without", "macro": m.macro,
            "refused": m.refused, "unfinished": m.unfinished, "decided": m.decided,
            "correct": m.correct, "pcs": round(m.pcs, 4), "se": round(m.se, 4),
            "holds": holds(m.pcs, m.se) if m.decided else True}


def readme(frame: pd.DataFrame, x: np.ndarray) -> str:
    means = ", ".join(f"{c:g} s: {m:.4f}" for c, m in zip(CYCLES, x.mean(axis=0)))
    reversed_pct = 100 * float(np.mean(x[:, 0] > x[:, 1]))
    lines = [
        "# KN on counts: its probability of correct selection, measured",
        "",
        f"`make kn-check` (`python -m cell.reporting.kn_report reports/kn`). Each row is {MACRO:,}",
        "independent selection problems with a known best, asked for a probability of correct",
        f"selection of {PCS:g}; KN ([docs/usage.md](../../docs/usage.md#selection-of-the-best-kn))",
        "screens them with its first-stage rule (`with`) and without it (`without`: every first",
        "stage taken at face value, as before the rule).",
        "",
        f"- **simulated**: parts missed by the fixed-cycle robot in runs of {PARTS} parts "
        "(baseline scenario),",
        f"  at cycles of {', '.join(f'{c:g}' for c in CYCLES)} s; mean parts missed over a pool "
        f"of {POOL:,} replications",
        f"  on common random numbers: {means}. Each problem draws its replications from the pool",
        f"  with replacement, so these are the true means; δ = {simulated_delta(x):.4f}, the gap "
        "from the best to the",
        "  second. `CRN`: whole rows, so the points' counts move together as a sweep's do (the shorter",
        f"  cycle loses more than the next in {reversed_pct:.1f} % of the pool's replications, and KN's",
        "  eliminations fall the right way even on a first-stage variance of 0); `independent`:",
        "  each point's replication from a row of its own, counts that do not move together.",
        f"- **Poisson**: independent Poisson counts, mean {POISSON[0]:g} for the best and "
        f"{POISSON[1]:g} for {len(POISSON) - 1} others,",
        f"  δ = {POISSON_DELTA:g} (every other system exactly δ worse: the hardest case the "
        "guarantee covers).",
        "",
        "`refused`: problems whose first stage had two systems that never differed (the",
        "selection is refused with one line); `unfinished`: problems that reached 20,000",
        "replications with more than one system left (reported as not told apart, no choice);",
        "`pcs`: the share of the others (`decided`) that chose the best, with its standard error",
        f"`se`; `holds`: `pcs` at or above {PCS:g} minus `se`.",
        "",
    ]
    lines += table_head(COLUMNS)
    lines += [table_row(str(v) for v in row) for row in frame[COLUMNS].itertuples(index=False)]
    ruled = frame[frame["rule"] == "with"]
    failing = frame[(frame["rule"] == "without") & ~frame["holds"]]
    lines += ["", f"With the rule {int(ruled['holds'].sum())} of {len(ruled)} rows hold; without it "
              f"{len(failing)} of {len(frame) - len(ruled)} fall short"
              + (" (" + ", ".join(f"{r.case} n0 = {r.n0}: {r.pcs:.4f} ± {r.se:.4f}"
                                  for r in failing.itertuples()) + ")." if len(failing) else ".")]
    return "\n".join(lines) + "\n"


def write(out_dir: str | Path = "reports/kn") -> Path:
    x = pool()
    frame = pd.DataFrame([*simulated_rows(x), *poisson_rows()], columns=COLUMNS)
    with OutputDir(out_dir, FILES, option="DIR") as out:
        out.write_csv("pcs.csv", frame)
        out.write_text("README.md", readme(frame, x))
    return Path(out_dir)


if __name__ == "__main__":  # pragma: no cover
    from cell.plumbing.errors import CellError

    try:
        print(f"wrote {write(*sys.argv[1:2])}")
    except CellError as exc:
        print(f"cell.reporting.kn_report: error: {exc}", file=sys.stderr)
        sys.exit(2)
