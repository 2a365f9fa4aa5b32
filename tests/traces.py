"""A scenario fed a given trace: the baseline cell with ``arrivals.trace_csv`` written from a list
of inter-arrival times (named by their hash, so equal traces share a file)."""

from __future__ import annotations

import hashlib
from pathlib import Path

from cell.scenario.schema import Scenario, load_scenario


def trace_scenario(folder: Path, gaps: list[float], policy: str = "adaptive") -> Scenario:
    """The baseline cell fed ``gaps`` (inter-arrival times, s) as ``arrivals.trace_csv``."""
    text = "interarrival_s\n" + "".join(f"{g!r}\n" for g in gaps)
    path = folder / f"{hashlib.sha1(text.encode()).hexdigest()[:16]}.csv"
    path.write_text(text)
    return load_scenario("baseline", {"run.parts": len(gaps), "arrivals.trace_csv": str(path),
                                      "controller.policy": policy})
