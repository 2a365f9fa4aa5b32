"""Every number the README (and docs/model.md, docs/assumptions.md) quotes is the committed
report's, from one table; the commands it shows exist and its column tables are the records'.

Each row of :data:`NUMBERS` is a page, a phrase of it with its numbers written ``{}``, and the
values they must read in order (expressions over the committed reports, by the helpers below),
rounded to the digits printed.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from cell.cli.parser import COMMANDS
from cell.experiments.benchmark_runs import PARTS
from cell.reporting import published as thesis
from cell.sim.records import BELT_COLUMNS, PART_COLUMNS, SUMMARY_COLUMNS
from tests.reporting.test_reports_readme import agrees, phrase, prose

ROOT = Path(__file__).resolve().parents[2]
REPORTS = ROOT / "reports"
PAGES = {page: (ROOT / page).read_text(encoding="utf-8")
         for page in ("README.md", "docs/usage.md", "docs/model.md", "docs/assumptions.md")}
README = PAGES["README.md"]


def section(title: str) -> str:
    """A ``## `` section of the README or docs/usage.md, to the next ``## `` heading."""
    both = README + "\n" + PAGES["docs/usage.md"]
    start = both.index(title)
    end = both.find("\n## ", start + 1)
    return both[start:end if end > 0 else None]


def one(name: str, **keys: Any) -> pd.Series:
    """The one row of ``reports/NAME`` with the ``keys`` given (``__`` for a dot in a name)."""
    frame = pd.read_csv(REPORTS / name)
    for k, v in keys.items():
        col = frame[k.replace("__", ".")]
        frame = frame[(col - v).abs() < 1e-6 if isinstance(v, float) else col == v]
    assert len(frame) == 1, (name, keys)
    return frame.iloc[0]


def t71(policy: str, accounting: str, measure: str) -> float:
    return float(one("table_7_1/table_7_1.csv", policy=policy, ideal_cycle_s=22.5872,
                     accounting=accounting, measure=measure)["mean"])


def ad(measure: str) -> pd.Series:
    """The adaptive robot's row of the committed Table 7.1 sweep's summary."""
    return one("table_7_1/summary.csv", policy="adaptive", measure=measure)


def runs_of(measure: str) -> float:
    """A per-run mean of :func:`ad`, back to the count over all runs."""
    return float(ad(measure)["mean"] * ad(measure)["n"])


def wi(policy: str, measure: str, arrivals: str) -> pd.Series:
    return one("whatif/summary.csv", policy=policy, measure=measure, arrivals__params__name=arrivals)


def wd(policy: str, arrivals: str) -> tuple[float, float]:
    """The what-if's loss in parts delivered against the thesis's arrivals, and its half-width."""
    r = one("whatif/differences.csv", policy=policy, measure="parts_delivered",
            arrivals__params__name=arrivals, versus=f"{policy} at arrivals.params = thesis")
    return -float(r["mean"]), float(r["ci_high"] - r["ci_low"]) / 2


def inside() -> int:
    """Published parts-missed, actual-cycle and IP figures inside the range of single runs."""
    t = pd.read_csv(REPORTS / "table_7_1" / "table_7_1.csv").query(
        "policy == 'non-adaptive' and accounting == 'thesis' and "
        "measure in ['parts_missed', 'actual_cycle_s', 'ip']")
    tol = t.measure.map(lambda m: 0.0 if m == "parts_missed" else 0.5e-4)
    return int(((t.thesis >= t.run_p2_5 - tol) & (t.thesis <= t.run_p97_5 + tol)).sum())


def vavg_gap() -> float:
    t = pd.read_csv(REPORTS / "table_7_1" / "table_7_1.csv").query(
        "measure == 'vavg_r4_in_s' and accounting == 'thesis'").dropna(subset=["thesis"])
    return float((t["mean"] - t.thesis).abs().max())


def sensor(arrivals: str) -> list[float]:
    """The advantage with the ideal look-ahead, with a perfect sensor at the drop point, and
    how much the first overstates the second (%)."""
    t = pd.read_csv(REPORTS / "sensor" / "sensor.csv")
    ideal, ref = (float(t[(t.arrivals == arrivals) & (t.sensor == s)]["delivered_vs_fixed"].iloc[0])
                  for s in ("ideal", "reference"))
    return [ideal, ref, 100 * (ideal - ref) / ref]


def stress() -> list[int]:
    a = pd.read_csv(REPORTS / "stress" / "stress.csv").query("policy == 'adaptive'")
    return [int((a.delivered_vs_fixed_ci_low > 0).sum()), len(a)]


def layout_study() -> list[float]:
    """reports/layout: the fewest and most places with which the fixed robot loses no more parts
    than the adaptive robot, at how many arrival points, and where two fixed robots lose fewer
    than the adaptive robot and than the fixed robot with 5 places."""
    t = pd.read_csv(REPORTS / "layout" / "layout.csv")
    found, beat_adaptive, beat_buffer, n = [], 0, 0, 0
    for _, point in t.groupby(["cv", "mean_s"]):
        lost = dict(zip(point["layout"], point["lost"]))
        n += 1
        enough = [k for k in (0, 1, 2, 3, 5) if lost[f"fixed, {k} places"] <= lost["adaptive, 0 places"]]
        if enough:
            found.append(min(enough))
        beat_adaptive += lost["two fixed robots"] < lost["adaptive, 0 places"]
        beat_buffer += lost["two fixed robots"] < lost["fixed, 5 places"]
    return [min(found), max(found), len(found), n, beat_adaptive, n, beat_buffer, n]


def wear() -> list[float]:
    from cell.reporting.maps.reliability import flip_exponent, verdicts

    v = verdicts(pd.read_csv(REPORTS / "reliability" / "reliability.csv"))
    r = v.iloc[-1]
    return [flip_exponent(v), r["wear_exponent"], r["shortest_cycle_s"], 100 * (1 - r["mtbf_ratio"]),
            r["down_fixed_h"], r["down_adaptive_h"]]


def bench() -> list[float]:
    """reports/benchmark/runs.csv: the headline's figures (cell/reporting/benchmark.py)."""
    r = pd.read_csv(REPORTS / "benchmark" / "runs.csv")
    return [len(r), PARTS, r["point"].nunique(), r["replication"].nunique(),
            *(100 * r[c].sum() / r["optimum"].sum() for c in ("adaptive", "learned", "non-adaptive")),
            int(r["exact"].sum()), len(r)]


def mt(model: str, *keys: str) -> list[float]:
    """reports/mintime/cycles.json's figures of one timing model."""
    doc = json.loads((REPORTS / "mintime" / "cycles.json").read_text())["models"]
    return [float(doc[model][k]) for k in keys or ("R2_s", "R4_s", "cycle_thesis_logic_s")]


def opt() -> dict[str, Any]:
    """reports/optimize: the best trial, the feasible trials within the selection's δ of it,
    KN's candidates, the loss at the slowest belts, and the trials at either end of the
    nominal cycle's range (its lowest and highest quarter, every trial that ran)."""
    import yaml

    trials = pd.read_csv(REPORTS / "optimize" / "trials.csv")
    best = pd.read_csv(REPORTS / "optimize" / "best.csv").iloc[0]
    study = yaml.safe_load((ROOT / "scenarios" / "optimize.yaml").read_text())
    prices = yaml.safe_load((ROOT / "scenarios" / "costed.yaml").read_text())["costs"]
    feasible = trials[trials["feasible"]]
    near = feasible[(feasible["cost_per_good_part"] - best["cost_per_good_part"]).abs()
                    <= study["select"]["delta"]]
    ran = trials[trials["refused"].isna()]
    low, high = study["vary"]["controller.nominal_cycle_s"]["low"], study["vary"][
        "controller.nominal_cycle_s"]["high"]
    cycle = ran["controller.nominal_cycle_s"]
    ends = [ran[(cycle >= a) & (cycle <= b)] for a, b in
            ((high - (high - low) / 4, high), (low, low + (high - low) / 4))]
    belt = ran["belts.input_nominal_in_s"]
    return {"best": best, "near": [len(near), len(feasible), near["cost_per_good_part"].min(),
                                   near["cost_per_good_part"].max()],
            "candidates": len(pd.read_csv(REPORTS / "optimize" / "selection.csv")),
            "parts": prices["part_value"] / best["cost_per_good_part"],
            "energy_pct": 100 * best["energy_per_good_part_wh"] / 1000 * prices["energy_per_kwh"]
            / best["cost_per_good_part"],
            "slow": [ran[(belt - 1.10).abs() < 1e-9]["parts_missed"].min(),
                     ran[(belt - 1.00).abs() < 1e-9]["parts_missed"].min(),
                     ran[(belt - 1.00).abs() < 1e-9]["parts_missed"].max()],
            "ends": [e[m].mean() for m in ("vavg_r4_in_s", "arm_energy_per_transfer_j",
                                           "energy_per_good_part_wh", "parts_missed") for e in ends],
            "quarters": [high - (high - low) / 4, high, low, low + (high - low) / 4]}


def year_headline() -> list[float]:
    """The worked year's OEE of each policy (both crews), the parts a year between them, and
    the second shift's crew's worth to the adaptive robot with its interval, and in OEE."""
    shifts = pd.read_csv(REPORTS / "year" / "shifts.csv").query("shift == 'all'")
    crews = pd.read_csv(REPORTS / "year" / "crews.csv").query("policy == 'adaptive'")
    both = shifts[shifts.crew == "both shifts"].set_index("policy")
    parts = crews.set_index("measure").loc["parts_delivered"]
    return [both.loc["adaptive", "oee"], both.loc["non-adaptive", "oee"],
            both.loc["adaptive", "parts_delivered"] - both.loc["non-adaptive", "parts_delivered"],
            parts["difference"], parts["ci_low"], parts["ci_high"],
            100 * crews.set_index("measure").loc["oee", "difference"]]


DYN, KIN, CONST = "minimum-time (dynamic)", "minimum-time (kinematic)", "constant-rate"
#: (page, a phrase of it with its numbers as ``{}``, the values they must read, in order)
NUMBERS: list[tuple[str, str, str]] = [
    ("README.md", "range of 95 % of single runs ({} of 18), and Vavg R IV matches to {} in/s",
     "inside(), vavg_gap()"),
    ("README.md", "bookkeeping loses {} parts of 500 on average (the thesis: 206) at an actual cycle "
     "of {} s (54.1660); a physically consistent robot loses {} at {} s",
     "*[t71('non-adaptive', a, m) for a in ('thesis', 'wallclock') for m in ('parts_missed', "
     "'actual_cycle_s')]"),
    ("README.md", "sets all {} parts down within 45 ± 0.25 in ({} off spacing)",
     "runs_of('parts_delivered') - ad('parts_delivered')['n'], runs_of('spacing_outside_tol')"),
    ("README.md", "Its step-6.2 IP is {} ({} % from the requested cycle); the published 1.0214 (\"within "
     "2.1 %\") is reproduced, {} ({} %)",
     "t71('adaptive', 'thesis', 'ip'), *[ad(m)['mean'] for m in ('cycle_vs_nominal_pct', "
     "'ip_thesis_memoryless', 'cycle_vs_nominal_memoryless_pct')]"),
    ("README.md", "the same draws at {} of {} points", "*stress()"),
    ("README.md", "the fixed-cycle robot needs {} to {} places of buffer to lose no more parts than the "
     "adaptive robot (at {} of {} arrival points); a second fixed-cycle robot loses fewer parts than "
     "the adaptive robot at {} of {} and than the fixed robot with 5 places at {} of {}",
     "*layout_study()"),
    ("README.md", "drop point: {} against {} parts per 500 on the thesis arrivals (the ideal look-ahead "
     "overstates it by {}%) and {} against {} parts per 500 on the spread arrivals (the ideal "
     "look-ahead overstates it by {}%)", "*sensor('thesis'), *sensor('spread')"),
    ("README.md", "wear exponent above p ≈ {}). At p = {} the fixed robot at {} s has {} % shorter mean "
     "time between wear stops than the adaptive robot, {} against {} h of downtime a year", "*wear()"),
    ("README.md", "the adaptive robot's OEE is {} against {} for the fixed cycle, {} more parts a "
     "year; a repair crew on the second shift as well as the first is worth {} parts a year to the "
     "adaptive robot (95 % CI {} to {}) and {} points of OEE", "*year_headline()"),
    ("README.md", "an estimated dynamic model it is {} s, with assumed stepper acceleration bounds {} s",
     "*mt(DYN, 'cycle_thesis_logic_s'), *mt(KIN, 'cycle_thesis_logic_s')"),
    ("README.md", "Over {} runs of {} parts ({} arrival patterns x {}), the thesis's adaptive controller "
     "delivers {} % of the hindsight optimum, the learned controller {} % and the fixed cycle {} %; "
     "the optimum is proved (the MILP's bound met) in {} of the {} runs", "*bench()"),
    # the worked what-if
    ("README.md", "It loses {} parts per 500-part run on the thesis's arrivals; the faster supply alone "
     "costs {} ± {} more ({} lost); twice the spread alone changes almost nothing; both changes "
     "together cost {} ± {} more ({} lost)",
     "wi('non-adaptive', 'parts_missed', 'thesis')['mean'], *wd('non-adaptive', 'faster'), "
     "wi('non-adaptive', 'parts_missed', 'faster')['mean'], *wd('non-adaptive', 'both'), "
     "wi('non-adaptive', 'parts_missed', 'both')['mean']"),
    ("README.md", "shortens its cycle to {} s and delivers {} parts/hr against {}. With both changes it "
     "loses {} ± {} parts per run (single runs {}–{}) and still delivers {} parts/hr",
     "wi('adaptive', 'actual_cycle_wallclock_s', 'faster')['mean'], "
     "wi('adaptive', 'parts_per_hr_wallclock', 'faster')['mean'], "
     "wi('adaptive', 'parts_per_hr_wallclock', 'thesis')['mean'], "
     "wi('adaptive', 'parts_missed', 'both')['mean'], wd('adaptive', 'both')[1], "
     "*wi('adaptive', 'parts_missed', 'both')[['run_p2_5', 'run_p97_5']], "
     "wi('adaptive', 'parts_per_hr_wallclock', 'both')['mean']"),
    # the worked optimisation
    ("README.md", "an input belt at **{} in/s** with a nominal cycle of **{} s**, **{}** a good part "
     "({} parts lost)", "*opt()['best'][['belts.input_nominal_in_s', 'controller.nominal_cycle_s', "
     "'cost_per_good_part', 'parts_missed']]"),
    ("README.md", "all {} of the {} feasible trials cost within 0.001 of it ({} to {} a good part)",
     "*opt()['near']"),
    ("README.md", "re-running the {} best", "opt()['candidates']"),
    ("README.md", "as much as {} good parts' share of the cell's hourly costs, while the energy, {} Wh a "
     "good part, is {} % of a part's cost", "opt()['parts'], opt()['best']['energy_per_good_part_wh'], "
     "opt()['energy_pct']"),
    ("README.md", "(at 1.10 in/s {} parts a run at the least, at 1.00 in/s {} to {})", "*opt()['slow']"),
    ("README.md", "over the trials with a nominal cycle of {}–{} s against those at {}–{} s",
     "*opt()['quarters']"),
    ("README.md", "the mean R IV speed is {} against {} in/s, each transfer draws {} against {} J from "
     "the arm's drives … the energy per good part is {} against {} Wh, and {} parts are lost a run "
     "against {}", "*opt()['ends']"),
    # docs/model.md: the departures' table (adaptive Table 7.1 runs) and the planner's cycles
    ("docs/model.md", "on the thesis's arrivals (adaptive, {} runs of {} parts)",
     "ad('parts_arrived')['n'], ad('parts_arrived')['mean']"),
    ("docs/model.md", "and the robot waits (limit CODE). | {} parts a run |",
     "ad('limit_input_ceiling')['mean']"),
    ("docs/model.md", "the fastest belt the robot can follow down to LO (limit CODE). | {} parts a run |",
     "ad('limit_input_tracking')['mean']"),
    ("docs/model.md", "(limits CODE, CODE). | R IV: {} parts a run; R II never |",
     "ad('limit_r4_peak')['mean']"),
    ("docs/model.md", "| constant rates (the thesis) | {} | {} | {} |", "*mt(CONST)"),
    ("docs/model.md", "| planner, velocity and assumed acceleration bounds | {} | {} | {} |", "*mt(KIN)"),
    ("docs/model.md", "| planner, velocity bounds and the estimated dynamic model | {} | {} | {} |",
     "*mt(DYN)"),
    ("docs/assumptions.md", "R IV's fastest time is {} s against {} s at constant rates; with the "
     "acceleration bounds instead, {} s", "*[mt(m, 'R4_s')[0] for m in (DYN, CONST, KIN)]"),
]


@pytest.mark.parametrize("page,template,values", NUMBERS, ids=[f"{p}:{t[:40]}" for p, t, _ in NUMBERS])
def test_a_number_quoted_is_the_committed_reports(page: str, template: str, values: str) -> None:
    found = phrase(template).search(prose(PAGES[page]))
    assert found, f"{page} no longer says: {template}"
    for printed, expected in zip(found.groups(), eval(f"[{values}]"), strict=True):  # noqa: S307
        assert agrees(printed, float(expected)), (printed, expected)


#: (phrase of docs/model.md's departures table, what never happens: counts zero in every run)
NEVER = [("is **let go** (limits CODE, CODE). | never reached |", ["limit_input_floor"]),
         ("| on Table 7.1's adaptive runs, with the spacing contract: never",
          ["limit_output_floor", "limit_output_ceiling", "spacing_outside_tol"]),
         ("| R IV: 1.1 parts a run; R II never |", ["limit_r2_peak"]),
         ("times the fastest cycle apart can never touch. | never (", ["parts_held", "feed_delay_max_s"])]


@pytest.mark.parametrize("text,measures", NEVER)
def test_never_in_docs_model_is_zero_in_every_run(text: str, measures: list[str]) -> None:
    assert text in prose(PAGES["docs/model.md"])
    assert [runs_of(m) for m in measures] == [0] * len(measures)   # counts and maxima


#: Published figures of the thesis, which the README may quote as they are.
PUBLISHED = {f"{v:.4f}" for row in thesis.TABLE_7_1.values() for v in row} | {
    "206", "1.0214", "2.1", "20.0907", "22.5872", "41.2"}
#: The experiments' own settings (not results): confidence, sizes, the map's ranges.
INPUTS = {"95", "200", "500", "0.05", "1", "0.9", "1.3", "45", "0.25", "5", "18", "0"}


def test_every_number_of_the_results_is_checked() -> None:
    """No figure in 'Results at a glance' or the what-if escapes the table above."""
    text = prose(README)
    covered = [range(*m.span(g)) for _, t, _ in NUMBERS for m in phrase(t).finditer(text)
               for g in range(1, m.re.groups + 1)]
    for title, upto in (("## Results at a glance", "## The command line"),
                        ("### What if parts came", "### Arrivals from your own log")):
        start = text.index(title)
        for m in re.finditer(r"(?<![\w.§/])[−-]?\d[\d,]*(?:\.\d+)?", text[start:text.index(upto)]):
            at = start + m.start()
            if re.search(r"(Table|step|steps|eq\.|Fig\.|§|R I+V?|-)\s*$", text[at - 7:at]) \
                    or m.group(0) in PUBLISHED | INPUTS:
                continue   # a reference (Table 7.1, step 6.2, eq. 6.9) or a published figure
            assert any(at in r for r in covered), f"unchecked {m.group(0)!r}: {text[at - 40:at + 20]!r}"


def test_every_command_shown_exists() -> None:
    text = README + PAGES["docs/usage.md"]
    assert {n for n in re.findall(r"`cell ([a-z]+)[ `]", text)} <= set(COMMANDS)
    for target in re.findall(r"`make ([a-z-]+)`", text):
        assert re.search(rf"^{target}:", (ROOT / "Makefile").read_text(), re.M), target


def test_the_column_tables_are_the_record_types() -> None:
    def names(table: str) -> list[str]:
        cells = [line.split("|")[1] for line in table.splitlines() if line.startswith("|")]
        return [n for cell in cells for n in re.findall(r"`([a-z0-9_]+)`", cell)]

    text = section("## Running the cell")
    documented = names(text[text.index("`parts.csv`, one row"):text.index("`belts.csv`, one row")])
    for first, last in (("v_r1_in_s", "v_r4_in_s"), ("r1_s", "r4_s")):   # written as ranges
        i = documented.index(first)
        assert documented[i + 1] == last
        documented[i:i + 2] = [first.replace("1", str(k)) for k in (1, 2, 3, 4)]
    assert documented == list(PART_COLUMNS)
    belts = re.search(r"`belts.csv`, one row per speed change: (.*)\.", text).group(1)
    assert re.findall(r"`([a-z_]+)`", re.sub(r"\([^)]*\)", "", belts)) == BELT_COLUMNS
    assert names(text[text.index("`summary.csv`, one row"):]) == SUMMARY_COLUMNS
