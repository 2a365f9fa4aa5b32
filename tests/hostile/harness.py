"""The hostile-input suite's harness: run ``cell`` in-process and hold it to its promise.

The promise (README, docs/): bad input is one line on stderr naming the file, the key and
the value, exit code 2, and nothing written; accepted input runs sanely (exit 0, no Python
warning or traceback, parts conserved, every summary value finite where it is defined); outputs appear
whole or not at all.  Each call of :func:`cli` is one case; the session's count is printed
at the end of the run (``hostile inputs: N cases ...``), after pytest's own summary line.

One case per rule.  A *rule* is one condition the code checks (a bound, finiteness, a type, a
file's encoding, an output's parent being a directory, one step of the output protocol), as
reached through one way in (a command's option, a scenario key, a file, ``--set``).  Two cases
that meet the same condition through the same way in, with different values (``-3`` beside
``0`` below a bound, ``EDQUOT`` beside ``ENOSPC`` in the same branch, a ``{`` beside a ``[``
nested too deep), test the rule twice: one of them goes.  The same condition through another
way in (a key of another section, ``--set`` beside a file, another command wiring a shared
check) is another rule, kept with one case; a shared check's every condition is walked
through one command only.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

from cell.cli.main import main

WHERE = ("in-process", "subprocess", "kill step")
OUTCOMES = ("refused", "ran", "other")


@dataclass
class Case:
    """One hostile input: where it ran, and how it was judged (None until judged: "other")."""

    where: str
    outcome: str | None = None

    def judged(self, outcome: str) -> None:
        """The first judgement stands: a result checked twice is still one case."""
        if self.outcome is None:
            self.outcome = outcome


CASES: list[Case] = []


def case(where: str, outcome: str | None = None) -> Case:
    """A new case of the session (``where``: one of :data:`WHERE`)."""
    assert where in WHERE and outcome in (None, *OUTCOMES)
    CASES.append(Case(where, outcome))
    return CASES[-1]


def counts() -> Counter[str]:
    """The session's cases by where they ran and by outcome; each breakdown sums to "cases"."""
    out: Counter[str] = Counter(cases=len(CASES))
    for c in CASES:
        out[c.where] += 1
        out[c.outcome or "other"] += 1
    return out


def summary_line(n: Counter[str]) -> str:
    """The line printed after pytest's summary (an error if a breakdown does not add up)."""
    where, outcomes = sum(n[w] for w in WHERE), sum(n[o] for o in OUTCOMES)
    if not where == outcomes == n["cases"]:
        raise AssertionError(f"hostile counts do not add up: {dict(n)}")
    return (f"hostile inputs: {n['cases']} cases ({n['in-process']} in-process, {n['subprocess']} in "
            f"subprocesses, {n['kill step']} kill steps): {n['refused']} refused in one line, "
            f"{n['ran']} ran sanely, {n['other']} checked otherwise (kill steps, --help)")


@dataclass
class Result:
    argv: list[str]
    code: int
    out: str
    err: str
    case: Case

    @property
    def err_lines(self) -> list[str]:
        return self.err.splitlines()


def cli(*argv: object) -> Result:
    """``cell ARGV`` in this process: exit code, stdout and stderr; one case of the suite."""
    args = [os.fspath(a) if isinstance(a, os.PathLike) else str(a) for a in argv]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(args)
    return Result(args, code, out.getvalue(), err.getvalue(), case("in-process"))


def tree(path: Path) -> dict[str, bytes] | None:
    """Every file under ``path`` with its bytes (None if ``path`` does not exist)."""
    try:
        if not path.exists():
            return None
    except OSError:  # a name too long to exist
        return None
    if path.is_file():
        return {"": path.read_bytes()}
    return {str(p.relative_to(path)): p.read_bytes() for p in sorted(path.rglob("*")) if p.is_file()}


def refused(res: Result, *needles: str, nothing_in: Path | None = None,
            before: dict[str, bytes] | None = None) -> str:
    """Exit 2, exactly one line on stderr (``cell: error: ...``) holding every needle, no
    traceback; ``nothing_in`` absent, or unchanged from ``before``."""
    res.case.judged("refused")
    assert res.code == 2, f"{res.argv}: exit {res.code}\n{res.err[-2000:]}"
    lines = res.err_lines
    assert len(lines) == 1, f"{res.argv}: {len(lines)} lines on stderr:\n{res.err[:3000]}"
    line = lines[0]
    assert line.startswith("cell: error: ") and "Traceback" not in res.err, line
    assert len(line) <= 1100, f"a {len(line)}-character line"
    for needle in needles:
        assert needle in line, f"{needle!r} not in: {line}"
    if nothing_in is not None:
        assert tree(nothing_in) == before, f"{nothing_in} changed by a refused command"
        parent = nothing_in.parent
        leftovers = [p.name for p in parent.iterdir() if ".cell-" in p.name] if tree(parent) is not None \
            and parent.is_dir() else []
        assert not leftovers, leftovers
    return line


#: Summary columns that may be empty (NaN): undefined for a policy or for too few parts.
MAY_BE_UNDEFINED = {"ip_wallclock", "ip_thesis", "cycle_vs_nominal_pct", "ip_thesis_memoryless",
                    "cycle_vs_nominal_memoryless_pct", "thesis_slack_s", "actual_cycle_wallclock_s",
                    "parts_per_hr_wallclock", "spacing_min_in", "spacing_max_in", "vavg_r4_in_s",
                    "r4_s", "output_speed_min_in_s", "output_speed_max_in_s",
                    "actual_cycle_thesis_s", "parts_per_hr_thesis",
                    # no robot failure (MTBF, MTTR), no part delivered (P, Q and OEE)
                    "mtbf_observed_s", "mttr_observed_s", "performance", "quality", "oee"}
#: No quantity of this model comes near this (times up to 1e6 s a part, 1e7 parts).
SANE = 1e14


#: What pandas' read_csv reads as NaN (its default na_values).
NA = {"", "#N/A", "#N/A N/A", "#NA", "-1.#IND", "-1.#QNAN", "-NaN", "-nan", "1.#IND", "1.#QNAN",
      "<NA>", "N/A", "NA", "NULL", "NaN", "None", "n/a", "nan", "null"}


def _number(text: str) -> float | str:
    """A CSV field as pandas reads it: NaN for :data:`NA`, a number a float, else the text."""
    if text in NA:
        return math.nan
    try:
        return float(text)
    except ValueError:
        return text


def _read_csv(path: Path) -> list[dict[str, float | str]]:
    """The rows of a CSV file, each field read by :func:`_number` (the csv module: pandas'
    read_csv cost a third of a case that ran)."""
    with open(path, newline="", encoding="utf-8") as f:
        return [{k: _number(v) for k, v in row.items()} for row in csv.DictReader(f)]


def ran_sanely(res: Result, out: Path, parts: int) -> SimpleNamespace:
    """Exit 0, nothing on stderr but the command's own one-line warnings, the whole set, ``parts``
    conserved, summary values finite and sane; the summary's row (its columns as attributes)."""
    res.case.judged("ran")
    assert res.code == 0, f"{res.argv}: exit {res.code}: {res.err[-2000:]}"
    noise = [line for line in res.err_lines if not line.startswith("cell: warning: ")]
    assert not noise, f"{res.argv}: stderr of an accepted run: {res.err[:2000]}"
    run_set = ["belts.csv", "parts.csv", "summary.csv"]
    # a run that can stop (failures:, or wear: on) writes its stops and states too: whole sets
    assert sorted(p.name for p in out.iterdir()) in (
        run_set, sorted([*run_set, "failures.csv", "states.csv"]))
    (row,) = _read_csv(out / "summary.csv")
    summary = SimpleNamespace(**row)
    rows = _read_csv(out / "parts.csv")
    warmup = int(row.get("warmup_parts", 0))  # parts left out of the measures
    assert len(rows) == parts and summary.parts_arrived == parts - warmup
    assert summary.parts_arrived == summary.parts_delivered + summary.parts_missed + summary.parts_in_cell
    for name, value in row.items():
        if name in ("scenario", "policy", "seed", "nominal_from") or isinstance(value, str):
            continue
        if math.isnan(value):
            assert name in MAY_BE_UNDEFINED, f"{res.argv}: summary {name} is empty"
        else:
            assert math.isfinite(value) and abs(value) < SANE, f"{res.argv}: summary {name} = {value}"
    numbers = [v for r in rows for v in r.values() if isinstance(v, float) and not math.isnan(v)]
    huge = [v for v in numbers if not abs(v) < SANE]
    assert not huge, f"{res.argv}: parts.csv holds {huge[:3]}"
    arrivals = [r["arrival_s"] for r in rows]
    assert all(b >= a for a, b in zip(arrivals, arrivals[1:]) if not (math.isnan(a) or math.isnan(b)))
    return summary
