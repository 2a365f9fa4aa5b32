"""Shared fixtures: the repository's scenario files and the thesis's cell, solved once."""

from __future__ import annotations

import os
import re
import signal
from collections import Counter
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from hypothesis import settings

from cell.scenario import catalog
from cell.scenario.schema import Scenario, default_scenario, load_scenario
from cell.sim.physics_checks import step_table
from cell.sim.policy_setup import constants
from cell.sim.timing_cache import robot_timing

# CI (.ci/run) sets HYPOTHESIS_PROFILE=ci: each property test draws the same examples every run,
# so a red CI is a change's doing; elsewhere each run draws anew and may find a new failure
# (add it as an @example when it is mended).
settings.register_profile("ci", derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

# The suite's own disk cache (cell.plumbing.cache), in this checkout's .pytest_cache: other
# checkouts' code (another fingerprint) cannot replace its entries mid-run, and a user's
# ~/.cache is left alone.  Subprocesses inherit it; tests of the cache set their own.
os.environ["XDG_CACHE_HOME"] = str(Path(__file__).resolve().parent.parent / ".pytest_cache"
                                   / "xdg")


def pytest_configure(config: pytest.Config) -> None:
    """Commands are started as a terminal starts them, with SIGINT at its default, even when
    pytest itself was started ignoring it (in a shell script's background job): cell keeps a
    SIGINT it was started ignoring ignored, and the signal tests send theirs to a command."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        try:
            signal.signal(signal.SIGINT, signal.default_int_handler)
        except ValueError:  # not the main thread: left as it is
            pass


@pytest.fixture(scope="session")
def thesis_cell() -> Scenario:
    """The thesis's cell: every default, and the ideal cycle the thesis quotes (22.5872 s;
    left out, the nominal cycle is the arrivals' own mean, 22.586 s for eq. 6.9)."""
    return default_scenario().with_overrides({"controller.nominal_cycle_s": 22.5872})


@pytest.fixture(scope="session")
def baseline() -> Scenario:
    return load_scenario(catalog.path("baseline"))


@pytest.fixture(scope="session")
def table(thesis_cell):
    """The thesis's path solved into its joint-step table."""
    return step_table(thesis_cell)


@pytest.fixture(scope="session")
def timing(thesis_cell):
    return robot_timing(thesis_cell)


@pytest.fixture(scope="session")
def k(thesis_cell, timing):
    """The policies' constants for the thesis's cell."""
    return constants(thesis_cell, timing)


@pytest.fixture
def unrendered(monkeypatch: pytest.MonkeyPatch) -> None:
    """Figures laid out (texts, ticks, their warnings) but not rasterised: each PNG file holds
    only the signature (tests/reporting/conftest.py).  For tests that read tables, markdown and
    CSVs, not pixels: a sweep's report draws a figure a measure."""
    from matplotlib.figure import Figure

    from tests.reporting.conftest import unrendered_savefig

    monkeypatch.setattr(Figure, "savefig", unrendered_savefig)


@pytest.fixture
def unlaid(monkeypatch: pytest.MonkeyPatch) -> None:
    """Figures built but neither laid out nor rasterised (a figure's layout is most of a save's
    time): for tests of where a report's files go and of what its tables, markdown and messages
    say, which read no figure and turn no warning into an error.  A figure's layout and pixels
    are checked where a test reads them: tests/reporting/test_figures.py (every thesis figure),
    test_experiment_plots.py (a report's), and the ``unrendered`` tests that read its texts."""
    from matplotlib.figure import Figure

    from tests.reporting.conftest import unlaid_savefig

    monkeypatch.setattr(Figure, "savefig", unlaid_savefig)


# --------------------------------------------------------------------------- sweep stand-ins
# The sweep runner takes the replication as a function; these small deterministic stand-ins
# draw from the stream they are given (module-level, so worker processes can run them).
def weibull_interarrivals(rng: np.random.Generator, n: int) -> np.ndarray:
    """Eq. 6.9 by inverse cdf: T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038 (docs/model.md)."""
    return 17.6019 + 5.4342 * (-np.log1p(-rng.random(n))) ** 0.2038


def thesis_bookkeeping(scenario, seed) -> dict:
    """A stand-in replication: the reconstruction (docs/accounting.md) of the thesis's bookkeeping
    (lost when T_i < C - s, s = 0.23 s; D_i = T_i, + C when lost) beside a naive
    wall clock (a part is lost when the robot is still busy), from the stream given."""
    rng = np.random.default_rng(seed)
    c = scenario.controller
    cycle = c.ideal_cycle_s if c.ideal_cycle_s is not None else c.nominal_cycle_s
    t = weibull_interarrivals(rng, scenario.run.parts)
    adaptive = c.policy == "adaptive"
    lost = np.zeros(t.size, bool) if adaptive else t < cycle - 0.23
    d = t + cycle * lost
    delivered = int((~lost).sum())
    actual_t = d.sum() / delivered
    ip_t = float(np.mean(t[1:] / (2 * d[:-1]))) if not adaptive else float(np.mean(t / t.mean()))
    arrivals = np.cumsum(t)
    ready, lost_w, done = 0.0, 0, []
    for a in arrivals:
        if a < ready and not adaptive:
            lost_w += 1
            continue
        ready = max(a, ready) + cycle
        done.append(ready)
    gaps = np.diff(done)
    actual_w = float(gaps.mean())
    r4 = 35.5424 / (9.9855 - (c.nominal_cycle_s - cycle))
    return {"policy": c.policy, "ideal_cycle_s": cycle, "parts_arrived": t.size,
            "parts_delivered": delivered, "parts_missed": int(lost.sum()),
            "actual_cycle_wallclock_s": actual_w, "actual_cycle_thesis_s": actual_t,
            "parts_per_hr_wallclock": 3600 / actual_w, "parts_per_hr_thesis": 3600 / actual_t,
            "vavg_r4_in_s": r4, "ip_wallclock": float(np.mean(t[1:] / gaps.mean())),
            "ip_thesis": ip_t, "spacing_min_in": 45.0, "spacing_max_in": 45.0,
            "first_u": np.random.default_rng(seed).random()}


def first_draw(scenario, seed) -> dict:
    """A tiny replication: the first uniform of the stream, and the cycle it ran at."""
    c = scenario.controller
    return {"u": np.random.default_rng(seed).random(), "cycle": c.ideal_cycle_s or -1.0,
            "parts": scenario.run.parts}


def write_sweep(tmp_path: Path, **fields) -> Path:
    doc = {"base": str(catalog.path("baseline")), "set": {"run.parts": 20},
           "policies": {"non-adaptive": {"controller.ideal_cycle_s": [22.0, 21.0]},
                        "adaptive": {}},
           "replications": 6, "seed": 7, "batch": 2}
    doc.update(fields)
    doc = {k: v for k, v in doc.items() if v is not None}
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


class Interrupt:
    """A replication that is 'killed' (KeyboardInterrupt) after ``after`` runs of ``of``."""

    def __init__(self, after: int, of=thesis_bookkeeping):
        self.after, self.calls, self.of = after, 0, of

    def __call__(self, scenario, seed):
        self.calls += 1
        if self.calls > self.after:
            raise KeyboardInterrupt
        return self.of(scenario, seed)


@pytest.fixture(scope="session")
def sweeps() -> SimpleNamespace:
    """The sweep stand-ins: ``write(tmp_path, **fields)`` a sweep file over baseline.yaml,
    ``bookkeeping`` and ``first_draw`` replications, ``Interrupt`` a replication killed
    after some runs."""
    return SimpleNamespace(write=write_sweep, bookkeeping=thesis_bookkeeping,
                           first_draw=first_draw, Interrupt=Interrupt)


# --------------------------------------------------------------------------- hostile counts
# The hostile-input suite counts its cases (tests/hostile/harness.py); under pytest-xdist each
# worker counts its own, sent to the controller, which prints the sum after pytest's summary.
_WORKER_COUNTS: Counter[str] = Counter()


def pytest_sessionfinish(session: pytest.Session) -> None:
    from tests.hostile.harness import counts

    if hasattr(session.config, "workeroutput"):  # an xdist worker: hand the counts over
        session.config.workeroutput["hostile_counts"] = dict(counts())


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error) -> None:  # noqa: ANN001 (pytest-xdist's hook)
    _WORKER_COUNTS.update(getattr(node, "workeroutput", {}).get("hostile_counts", {}))


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    from tests.hostile.harness import counts, summary_line

    total = counts() + _WORKER_COUNTS
    if total["cases"]:
        terminalreporter.write_line(summary_line(total))


#: Modules whose tests take seconds each (``pytest --durations``), run first: on two
#: workers a long test left to the end keeps one worker busy while the other idles.
SLOW_FIRST = ("tests/reporting/test_reports_regenerate.py", "tests/reporting/test_figures.py",
              "tests/plumbing/test_output_streams.py", "tests/experiments/test_optimize.py",
              "tests/arm/test_mintime_toppra.py", "tests/robust/", "tests/animate/",
              "tests/reporting/test_figures_cycles.py", "tests/arm/test_mintime.py")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    def rank(item: pytest.Item) -> int:
        path = item.nodeid.split("::")[0]
        return next((k for k, prefix in enumerate(SLOW_FIRST) if path.startswith(prefix)),
                    len(SLOW_FIRST))

    items.sort(key=rank)  # stable: within a rank, the collected order


# --------------------------------------------------------------------------- one worker a module
#: Test modules that hold a module-scoped fixture (or an ``xdist_group`` mark), by path from the
#: repository: each runs on one worker, so the fixture is computed once a suite, not once on
#: each worker (the figures' drawing, toppra's solutions, the fits, the reports' runs).
_TESTS = Path(__file__).resolve().parent
ONE_WORKER = frozenset(
    path.relative_to(_TESTS.parent).as_posix() for path in sorted(_TESTS.rglob("test_*.py"))
    if re.search(r"""scope=["'](module|class)["']|xdist_group""", path.read_text("utf-8")))


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):  # noqa: ANN001, ANN201 (xdist's hook)
    """``--dist loadgroup`` with each of ONE_WORKER's modules one unit of work.  xdist marks a
    group by appending ``@name`` to the test's node id on the worker, which pytest 9.2 no longer
    honours (the id is its ``_id``, not ``_nodeid``): the marks alone split the figures' module
    over both workers and drew every figure twice."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class ModulesTogether(LoadGroupScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            return path if path in ONE_WORKER else super()._split_scope(nodeid)

    return ModulesTogether(config, log)
