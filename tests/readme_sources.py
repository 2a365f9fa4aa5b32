"""What the README checks stand on (test_reports_readme.py): the README read as prose, its
phrases with numbers left open, the sources the numbers come from, and the claims' registry."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import scipy.stats

REPO = Path(__file__).resolve().parents[1]
README = REPO / "reports" / "README.md"
NUMBER = r"([−+-]?\d+(?:\.\d+)?)"


def prose(text: str) -> str:
    """The README as read: images, link targets and code spans dropped, whitespace collapsed."""
    text = re.sub(r"^!\[.*$", "", text, flags=re.MULTILINE)
    text = re.sub(r"\]\([^)]*\)", "]", text)
    text = re.sub(r"`[^`]*`", "CODE", text)
    return re.sub(r"\s+", " ", text)


def phrase(template: str) -> re.Pattern[str]:
    """A README phrase with its numbers written ``{}``: the rest matched literally."""
    parts = re.sub(r"\s+", " ", template).split("{}")
    return re.compile(NUMBER.join(re.escape(p).replace(r"\ ", " ") for p in parts))


def value(printed: str) -> float:
    return float(printed.replace("−", "-").replace("+", ""))


def agrees(printed: str, expected: float, tol: float | None = None) -> bool:
    """``printed`` is ``expected`` rounded to the digits shown (or within ``tol``)."""
    if tol is None:
        decimals = len(printed.split(".")[1]) if "." in printed else 0
        tol = 0.5 * 10.0 ** -decimals + 1e-9
    return abs(value(printed) - expected) <= tol


# --------------------------------------------------------------------------- the sources
@dataclass
class Sources:
    """Where the README's numbers come from, each computed once."""

    @cached_property
    def s(self) -> Any:
        from cell.scenario.schema import load_scenario

        return load_scenario("baseline")

    @cached_property
    def table(self) -> Any:
        from cell.sim.physics_checks import step_table

        return step_table(self.s)

    @cached_property
    def tl(self) -> Any:
        """The figures' nominal transfer (Fig. 15-21), moves timed on the joints' travel."""
        from cell.reporting.figures.motion import joint_travel_min_times, nominal_timeline

        return nominal_timeline(self.table, self.s, joint_travel_min_times(self.table))

    @cached_property
    def rates(self) -> np.ndarray:
        """(N-1, 5) dθ/dt × steps/rad of every move of the nominal transfer (Fig. 17-21)."""
        k = np.asarray(self.s.robot.motors.steps_per_rad)
        return np.diff(self.table.path.q_rad, axis=0) * k / self.tl.dt_s[1:, None]

    @cached_property
    def limits(self) -> np.ndarray:
        """(N-1, 5) maximum step rates at each move's load, linear in the load (§6.1)."""
        m = self.s.robot.motors
        k = np.asarray(m.steps_per_rad)
        no_load, full = np.asarray(m.max_rate_no_load_rad_s), np.asarray(m.max_rate_full_load_rad_s)
        load = self.table.path.load_oz[1:, None]
        return k * (no_load + (full - no_load) * load / m.full_load_oz)

    @cached_property
    def runs(self) -> Any:
        from cell.reporting.figures.runs import simulate_runs

        return simulate_runs(self.s)

    @cached_property
    def t71(self) -> pd.DataFrame:
        return pd.read_csv(REPO / "reports" / "table_7_1" / "table_7_1.csv")

    def published(self, measure: str, cycle: float = 22.5872, policy: str = "non-adaptive") -> float:
        """The thesis's figure as the committed report prints it beside ours."""
        t = self.t71
        row = t[(t.policy == policy) & (t.accounting == "thesis") & (t.measure == measure)
                & np.isclose(t.ideal_cycle_s, cycle)]
        assert len(row) == 1, (measure, cycle, policy)
        return float(row["thesis"].iloc[0])

    def regime_rows(self, r: int) -> np.ndarray:
        return self.table.path.regime[1:] == r

    @cached_property
    def k_point(self) -> int:
        return int(np.flatnonzero(self.table.path.regime == 3)[-1])

    @cached_property
    def draws(self) -> np.ndarray:
        """The run's inter-arrival times, as the feeder draws them (Fig. 13-14)."""
        from cell.reporting.figures.interarrival import draws

        return draws(self.s, self.s.run.parts)

    @cached_property
    def weibull(self) -> Any:
        a = self.s.arrivals
        return getattr(scipy.stats, a.distribution)(**dict(a.params))

    @cached_property
    def fig22(self) -> dict[str, Any]:
        from cell.reporting.figures.tip import (
            belt_speed_at,
            hand_moves,
            pick_transfer,
            tip_speeds,
            transfer_timeline,
        )

        run = self.runs.adaptive
        row = run.parts.iloc[pick_transfer(run)]
        tl = transfer_timeline(self.table, row)
        grasp, _ = hand_moves(self.table)
        hist = run.belts["input"]
        picked = run.parts[run.parts["picked"]]
        return {"row": row, "dt": tl.dt_s[grasp], "speed": tip_speeds(self.table, tl)[grasp - 1],
                "before": belt_speed_at(hist, row["pick_s"] - 1e-6),
                "after": belt_speed_at(hist, row["pick_s"]),
                "lags": (picked["pick_s"] - picked["at_bot_s"]).to_numpy()}


# --------------------------------------------------------------------------- the claims
Check = Callable[[Sources, list[str]], Iterable[tuple[Any, ...]]]
CLAIMS: list[tuple[re.Pattern[str], Check]] = []


def claim(template: str) -> Callable[[Check], Check]:
    def register(check: Check) -> Check:
        CLAIMS.append((phrase(template), check))
        return check
    return register


def points(f: Sources) -> dict[str, np.ndarray]:
    p, path = f.s.path, f.table.path
    return {"B": p.bot_in, "F": p.f_in, "G": p.g_in, "K": p.eot_in, "LO": path.xyz_in[path.lo],
            "TD": path.xyz_in[path.td], "base": f.s.cell.robot_base_in}
