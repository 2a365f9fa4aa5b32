"""The README and docs/usage.md against what they describe: every number the README quotes is
read from the committed reports, every command they show exists, the column tables are the record
types' fields, and every link and anchor between them resolves."""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import pytest

from cell.cli.main import COMMANDS
from cell.reporting import published as thesis
from cell.sim.records import BELT_COLUMNS, PART_COLUMNS, SUMMARY_COLUMNS

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
#: The reference the README points to for every command's files and rules.
USAGE = (ROOT / "docs" / "usage.md").read_text(encoding="utf-8")
#: The README and the docs page together, as a user reads them.
BOTH = README + "\n" + USAGE
REPORTS = ROOT / "reports"


def section(title: str) -> str:
    """A ``## `` section of the README or docs/usage.md, to the next ``## `` heading."""
    start = BOTH.index(title)
    end = BOTH.find("\n## ", start + 1)
    return BOTH[start:end if end > 0 else None]


def t71(policy: str, cycle: float, accounting: str, measure: str, column: str = "mean") -> float:
    frame = pd.read_csv(REPORTS / "table_7_1" / "table_7_1.csv")
    row = frame[(frame.policy == policy) & ((frame.ideal_cycle_s - cycle).abs() < 1e-6)
                & (frame.accounting == accounting) & (frame.measure == measure)]
    return float(row.iloc[0][column])


def summary(policy: str, measure: str, folder: str = "table_7_1", **keys: str) -> pd.Series:
    frame = pd.read_csv(REPORTS / folder / "summary.csv")
    sel = frame[(frame.policy == policy) & (frame.measure == measure)]
    for k, v in keys.items():
        sel = sel[sel[k] == v]
    return sel.iloc[0]


def whatif_diff(policy: str, measure: str, arrivals: str) -> pd.Series:
    frame = pd.read_csv(REPORTS / "whatif" / "differences.csv")
    sel = frame[(frame.policy == policy) & (frame.measure == measure)
                & (frame["arrivals.params.name"] == arrivals)]
    return sel.iloc[0]


def wif(policy: str, measure: str, arrivals: str) -> pd.Series:
    """A row of the what-if's summary: ``arrivals`` is the named arrivals setting."""
    return summary(policy, measure, "whatif", **{"arrivals.params.name": arrivals})


def half(row: pd.Series) -> float:
    return float(row["ci_high"] - row["ci_low"]) / 2


def stress_counts() -> tuple[int, int]:
    t = pd.read_csv(REPORTS / "stress" / "stress.csv")
    ad = t[t.policy == "adaptive"]
    return int((ad.delivered_vs_fixed_ci_low > 0).sum()), len(ad)


def wear_verdict(p: float | None = None) -> dict:
    """reports/reliability's verdict at exponent p (the largest swept if None), and its flip."""
    from cell.reporting.reliability import flip_exponent, verdicts

    v = verdicts(pd.read_csv(REPORTS / "reliability" / "reliability.csv"))
    row = v.iloc[-1] if p is None else v[v["wear_exponent"] == p].iloc[0]
    return {**row.to_dict(), "flip": flip_exponent(v)}


def mintime(model: str) -> float:
    doc = json.loads((REPORTS / "mintime" / "cycles.json").read_text())
    return float(doc["models"][model]["cycle_thesis_logic_s"])


def inside_count() -> int:
    frame = pd.read_csv(REPORTS / "table_7_1" / "table_7_1.csv")
    sel = frame[(frame.policy == "non-adaptive") & (frame.accounting == "thesis")
                & frame.measure.isin(["parts_missed", "actual_cycle_s", "ip"])]
    tol = sel.measure.map(lambda m: 0.0 if m == "parts_missed" else 0.5e-4)
    return int(((sel.thesis >= sel.run_p2_5 - tol) & (sel.thesis <= sel.run_p97_5 + tol)).sum())


def vavg_gap() -> float:
    frame = pd.read_csv(REPORTS / "table_7_1" / "table_7_1.csv")
    sel = frame[(frame.measure == "vavg_r4_in_s") & (frame.accounting == "thesis")
                & frame.thesis.notna()]
    return float((sel["mean"] - sel.thesis).abs().max())


def spacings_off() -> tuple[int, int]:
    row = summary("adaptive", "spacing_outside_tol")
    delivered = summary("adaptive", "parts_delivered")
    runs = int(row["n"])
    return round(float(row["mean"]) * runs), round((float(delivered["mean"]) - 1) * runs)


C = 22.5872
#: (a regular expression capturing one number in the README, the value it must show)
def sensor_advantage(arrivals: str, sensor: str) -> float:
    t = pd.read_csv(REPORTS / "sensor" / "sensor.csv")
    return float(t[(t["arrivals"] == arrivals) & (t["sensor"] == sensor)]["delivered_vs_fixed"].iloc[0])


def sensor_over(arrivals: str) -> str:
    ideal, ref = sensor_advantage(arrivals, "ideal"), sensor_advantage(arrivals, "reference")
    return f"{(ideal - ref) / ref:.0%}".rstrip("%")


CHECKS: list[tuple[str, Callable[[], str]]] = [
    (r"drop\s+point:\s+([\d.]+)\s+against\s+[\d.]+\s+parts\s+per\s+500\s+on\s+the\s+thesis",
     lambda: f"{sensor_advantage('thesis', 'ideal'):.1f}"),
    (r"drop\s+point:\s+[\d.]+\s+against\s+([\d.]+)\s+parts\s+per\s+500\s+on\s+the\s+thesis",
     lambda: f"{sensor_advantage('thesis', 'reference'):.1f}"),
    (r"on\s+the\s+thesis\s+arrivals\s+\(the\s+ideal\s+look-ahead\s+overstates\s+it\s+by\s+(\d+)%",
     lambda: sensor_over("thesis")),
    (r"and\s+([\d.]+)\s+against\s+[\d.]+\s+parts\s+per\s+500\s+on\s+the\s+spread",
     lambda: f"{sensor_advantage('spread', 'ideal'):.1f}"),
    (r"and\s+[\d.]+\s+against\s+([\d.]+)\s+parts\s+per\s+500\s+on\s+the\s+spread",
     lambda: f"{sensor_advantage('spread', 'reference'):.1f}"),
    (r"on\s+the\s+spread\s+arrivals\s+\(the\s+ideal\s+look-ahead\s+overstates\s+it\s+by\s+(\d+)%",
     lambda: sensor_over("spread")),
    (r"range of 95 % of single runs \((\d+) of 18\)", lambda: f"{inside_count()}"),
    (r"Vavg R IV matches to ([\d.]+) in/s", lambda: f"{vavg_gap():.5f}".rstrip("0")),
    (r"loses ([\d.]+) parts of 500 on average \(the thesis: 206\)",
     lambda: f"{t71('non-adaptive', C, 'thesis', 'parts_missed'):.1f}"),
    (r"actual cycle of\s+([\d.]+) s \(54\.1660\)",
     lambda: f"{t71('non-adaptive', C, 'thesis', 'actual_cycle_s'):.2f}"),
    (r"a physically consistent robot loses ([\d.]+) at",
     lambda: f"{t71('non-adaptive', C, 'wallclock', 'parts_missed'):.1f}"),
    (r"a physically consistent robot loses [\d.]+ at ([\d.]+) s",
     lambda: f"{t71('non-adaptive', C, 'wallclock', 'actual_cycle_s'):.2f}"),
    (r"parts down within 45 ± 0.25 in \((\d+) off spacing\)", lambda: f"{spacings_off()[0]}"),
    (r"sets all\s+([\d,]+) parts down within", lambda: f"{spacings_off()[1]:,}"),
    (r"Its step-6.2 IP is ([\d.]+)", lambda: f"{t71('adaptive', C, 'thesis', 'ip'):.4f}"),
    (r"\(([−\d.]+) % from the requested\s+cycle\)",
     lambda: f"{summary('adaptive', 'cycle_vs_nominal_pct')['mean']:.2f}".replace("-", "−")),
    (r"reproduced, ([\d.]+) \(",
     lambda: f"{summary('adaptive', 'ip_thesis_memoryless')['mean']:.4f}"),
    (r"reproduced, [\d.]+ \(([−\d.]+) %\)",
     lambda: f"{summary('adaptive', 'cycle_vs_nominal_memoryless_pct')['mean']:.2f}"
     .replace("-", "−")),
    (r"the same draws at (\d+) of \d+ points", lambda: f"{stress_counts()[0]}"),
    (r"the same draws at \d+ of (\d+) points", lambda: f"{stress_counts()[1]}"),
    (r"an estimated dynamic model it is ([\d.]+) s", lambda: f"{mintime('minimum-time (dynamic)'):.4f}"),
    (r"wear exponent above p ≈ ([\d.]+)", lambda: f"{wear_verdict()['flip']:.2f}"),
    (r"At p = (\d+) the fixed robot at", lambda: f"{wear_verdict()['wear_exponent']:g}"),
    (r"the fixed robot at ([\d.]+) s has \d+ %",
     lambda: f"{wear_verdict()['shortest_cycle_s']:.4f}"),
    (r"s has (\d+) % shorter mean time",
     lambda: f"{100 * (1 - wear_verdict()['mtbf_ratio']):.0f}"),
    (r"robot, ([\d.]+) against [\d.]+ h of downtime a year",
     lambda: f"{wear_verdict()['down_fixed_h']:.1f}"),
    (r"robot, [\d.]+ against ([\d.]+) h of downtime a year",
     lambda: f"{wear_verdict()['down_adaptive_h']:.1f}"),
    (r"acceleration bounds ([\d.]+) s", lambda: f"{mintime('minimum-time (kinematic)'):.4f}"),
    # the worked what-if
    (r"It loses ([\d.]+) parts per 500-part run on the thesis's arrivals",
     lambda: f"{wif('non-adaptive', 'parts_missed', 'thesis')['mean']:.1f}"),
    (r"alone costs ([\d.]+) ± [\d.]+ more",
     lambda: f"{-whatif_diff('non-adaptive', 'parts_delivered', 'faster')['mean']:.1f}"),
    (r"alone costs [\d.]+ ± ([\d.]+) more",
     lambda: f"{half(whatif_diff('non-adaptive', 'parts_delivered', 'faster')):.1f}"),
    (r"more \(([\d.]+) lost\); twice",
     lambda: f"{wif('non-adaptive', 'parts_missed', 'faster')['mean']:.1f}"),
    (r"together cost ([\d.]+) ± [\d.]+ more",
     lambda: f"{-whatif_diff('non-adaptive', 'parts_delivered', 'both')['mean']:.1f}"),
    (r"together cost [\d.]+ ± ([\d.]+) more",
     lambda: f"{half(whatif_diff('non-adaptive', 'parts_delivered', 'both')):.1f}"),
    (r"more \(([\d.]+) lost\): the extra",
     lambda: f"{wif('non-adaptive', 'parts_missed', 'both')['mean']:.1f}"),
    (r"shortens its cycle to ([\d.]+) s",
     lambda: f"{wif('adaptive', 'actual_cycle_wallclock_s', 'faster')['mean']:.2f}"),
    (r"and delivers ([\d.]+) parts/hr against",
     lambda: f"{wif('adaptive', 'parts_per_hr_wallclock', 'faster')['mean']:.1f}"),
    (r"parts/hr against\s+([\d.]+)\.",
     lambda: f"{wif('adaptive', 'parts_per_hr_wallclock', 'thesis')['mean']:.1f}"),
    (r"With both changes it loses ([\d.]+) ± [\d.]+ parts per run",
     lambda: f"{wif('adaptive', 'parts_missed', 'both')['mean']:.1f}"),
    (r"With both changes it loses [\d.]+ ± ([\d.]+) parts per run",
     lambda: f"{half(whatif_diff('adaptive', 'parts_delivered', 'both')):.1f}"),
    (r"\(single runs (\d+)–\d+\)",
     lambda: f"{wif('adaptive', 'parts_missed', 'both')['run_p2_5']:.0f}"),
    (r"\(single runs \d+–(\d+)\)",
     lambda: f"{wif('adaptive', 'parts_missed', 'both')['run_p97_5']:.0f}"),
    (r"still\s+delivers ([\d.]+) parts/hr",
     lambda: f"{wif('adaptive', 'parts_per_hr_wallclock', 'both')['mean']:.1f}"),
]


@pytest.mark.parametrize("pattern,value", CHECKS, ids=[c[0][:50] for c in CHECKS])
def test_a_number_the_readme_quotes_is_the_committed_reports(pattern, value):
    found = re.search(pattern, README)
    assert found, f"the README no longer says: {pattern}"
    assert found.group(1) == value()


#: Published figures of the thesis, which the README may quote as they are.
PUBLISHED = {f"{v:.4f}" for row in thesis.TABLE_7_1.values() for v in row} | {
    "206", "1.0214", "2.1", "20.0907", "22.5872", "41.2"}


#: The experiments' own settings (not results): confidence, sizes, the map's ranges.
INPUTS = {"95", "200", "500", "0.05", "1", "0.9", "1.3", "45", "0.25", "5", "18", "0"}


def test_every_number_of_the_results_is_checked():
    """No figure in 'Results at a glance' or the what-if escapes the checks above."""
    covered = {m.span(1) for pattern, _ in CHECKS for m in [re.search(pattern, README)] if m}
    for title in ("## Results at a glance", "### What if parts came"):
        start = README.index(title)
        text = section(title) if title.startswith("## ") else \
            README[start:README.index("\n### ", start + 1)]
        for m in re.finditer(r"(?<![\w.§/])[−-]?\d[\d,]*(?:\.\d+)?", text):
            value, span = m.group(0), (start + m.start(), start + m.end())
            before = text[max(0, m.start() - 7):m.start()]
            if re.search(r"(Table|step|steps|eq\.|Fig\.|§|R I+V?|-)\s*$", before):
                continue   # a reference (Table 7.1, step 6.2, eq. 6.9), not a figure
            if value in PUBLISHED or value in INPUTS:
                continue
            assert any(a <= span[0] and span[1] <= b for a, b in covered), \
                f"README quotes {value!r} at {text[max(0, m.start() - 40):m.end() + 10]!r} unchecked"


def column_names(table: str) -> list[str]:
    names = []
    for line in table.splitlines():
        cell = line.split("|")[1].strip() if line.startswith("|") else ""
        names += re.findall(r"`([a-z0-9_]+)`", cell)
    return names


def test_the_column_tables_are_the_record_types():
    text = section("## Running the cell")
    parts = text[text.index("`parts.csv`, one row"):text.index("`belts.csv`, one row")]
    documented = column_names(parts)
    expected = [c for c in PART_COLUMNS]
    # v_r1..v_r4 and r1..r4 are written as ranges
    for first, last in (("v_r1_in_s", "v_r4_in_s"), ("r1_s", "r4_s")):
        i = documented.index(first)
        assert documented[i + 1] == last
        documented[i:i + 2] = [first.replace("1", str(k)) for k in (1, 2, 3, 4)]
    assert documented == expected
    belts = re.search(r"`belts.csv`, one row per speed change: (.*)\.", text).group(1)
    assert re.findall(r"`([a-z_]+)`", re.sub(r"\([^)]*\)", "", belts)) == BELT_COLUMNS
    summary_table = text[text.index("`summary.csv`, one row"):]
    assert column_names(summary_table) == SUMMARY_COLUMNS


def test_every_command_shown_exists():
    for name in re.findall(r"`cell ([a-z]+)[ `]", BOTH):
        assert name in COMMANDS, name
    for target in re.findall(r"`make ([a-z-]+)`", BOTH):
        assert re.search(rf"^{target}:", (ROOT / "Makefile").read_text(), re.M), target


def test_links_point_at_files_that_exist():
    for link in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README):
        if not link.startswith("http"):
            assert (ROOT / link).exists(), link


def test_the_docs_minimum_time_figures_are_the_committed_report():
    """docs/model.md's table and docs/assumptions.md's R IV times are reports/mintime's."""
    cycles = json.loads((REPORTS / "mintime" / "cycles.json").read_text())["models"]
    model = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
    rows = {"constant rates (the thesis)": "constant-rate",
            "planner, velocity and assumed acceleration bounds": "minimum-time (kinematic)",
            "planner, velocity bounds and the estimated dynamic model": "minimum-time (dynamic)"}
    for label, key in rows.items():
        found = re.search(rf"\| {re.escape(label)} \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|", model)
        assert found, label
        c = cycles[key]
        assert found.groups() == (f"{c['R2_s']:.4f}", f"{c['R4_s']:.4f}",
                                  f"{c['cycle_thesis_logic_s']:.4f}"), label
    assumptions = (ROOT / "docs" / "assumptions.md").read_text(encoding="utf-8")
    found = re.search(r"R IV's fastest\s+time is ([\d.]+) s against ([\d.]+) s at constant rates; "
                      r"with the acceleration bounds instead,\s+([\d.]+) s", assumptions)
    assert found
    assert found.groups() == tuple(f"{cycles[k]['R4_s']:.4f}" for k in (
        "minimum-time (dynamic)", "constant-rate", "minimum-time (kinematic)"))
