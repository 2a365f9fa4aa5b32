"""cell optimize: the optimum of an exhaustive grid of the same model, resuming after a kill,
and bad study files (one line, exit 2, nothing written)."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from cell.cli.main import main
from cell.experiments.study import load_study, replicate
from tests.reporting.conftest import unlaid_savefig

BASE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"

FIXED = f"""base: {BASE}
set: {{run.parts: 60, controller.policy: non-adaptive}}
vary:
  controller.ideal_cycle_s: {{low: 20.1, high: 22.5, step: 0.3}}
objectives: [{{measure: parts_missed, goal: minimize}}]
trials: TRIALS
replications: 2
seed: 7
"""


def _study(tmp_path: Path, text: str, name: str = "study.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def whole(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """FIXED's 8 trials run unbroken (one worker), once for the module: the grid test reads its
    best, the killed-and-resumed run must equal its trials."""
    from matplotlib.figure import Figure

    folder = tmp_path_factory.mktemp("whole")
    path = _study(folder, FIXED.replace("TRIALS", "8"))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", unlaid_savefig)  # as the ``unlaid`` fixture
        assert main(["optimize", str(path), "--out", str(folder / "out")]) == 0
    return folder


def test_the_optimiser_finds_the_grid_optimum_of_the_fixed_cycle_robot(whole: Path) -> None:
    """The fixed-cycle robot's ideal cycle that loses fewest parts, on the same streams: the
    exhaustive grid (9 cycles) is the independent answer; 8 trials of TPE must reach its
    best within one part."""
    study = load_study(whole / "study.yaml")
    grid = {round(20.1 + 0.3 * i, 1): sum(r["parts_missed"] for r in replicate(
        study, {"controller.ideal_cycle_s": 20.1 + 0.3 * i}, range(2))) / 2 for i in range(9)}
    best = pd.read_csv(whole / "out" / "best.csv")
    assert best["parts_missed"].min() <= min(grid.values()) + 1.0
    assert grid[round(float(best["controller.ideal_cycle_s"].iloc[0]), 1)] <= min(grid.values()) + 1.0
    # the losses fall as the cycle shortens (Table 7.1): the optimum is near the shortest cycle
    assert float(best["controller.ideal_cycle_s"].iloc[0]) <= 21.0


def _completed(db: Path) -> int:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    try:
        s = optuna.load_study(study_name=optuna.get_all_study_names(f"sqlite:///{db}")[0],
                              storage=f"sqlite:///{db}")
    except Exception:  # noqa: BLE001 - not created yet
        return 0
    return len(s.get_trials(states=(optuna.trial.TrialState.COMPLETE,)))


#: ``cell optimize`` in a process that SIGKILLs itself as the 4th trial starts its runs: the 3
#: trials before it are complete in the study's database, the 4th is left running (no race with
#: the machine's speed, whatever its load).
KILLED_AT_THE_4TH_TRIAL = """
import os, signal, sys
import cell.experiments.optimize as optimize
real, calls = optimize.replicate, []
def replicate(*args, **kwargs):
    calls.append(1)
    if len(calls) == 4:
        os.kill(os.getpid(), signal.SIGKILL)
    return real(*args, **kwargs)
optimize.replicate = replicate
from cell.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.usefixtures("unlaid")
def test_a_killed_optimize_resumes_without_losing_or_repeating_a_trial(tmp_path: Path,
                                                                        whole: Path) -> None:
    path = _study(tmp_path, FIXED.replace("TRIALS", "8"))
    out = tmp_path / "out"
    cmd = [sys.executable, "-c", KILLED_AT_THE_4TH_TRIAL, "optimize", str(path), "--out", str(out)]
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=300)
    assert proc.returncode == -signal.SIGKILL
    before = _completed(out / "study.db")
    assert before == 3
    assert main(["optimize", str(path), "--out", str(out)]) == 2  # no --resume: refused
    assert main(["optimize", str(path), "--out", str(out), "--resume"]) == 0
    resumed = pd.read_csv(out / "trials.csv")
    assert len(resumed) == 8 and resumed["trial"].is_unique
    # the same as an unbroken run with the same seed (one worker): no trial lost or repeated
    unbroken = pd.read_csv(whole / "out" / "trials.csv")
    cols = ["controller.ideal_cycle_s", "parts_missed"]
    assert resumed[cols].reset_index(drop=True).equals(unbroken[cols].reset_index(drop=True))


BAD = {
    "unknown key": ("vary:\n  belts.no_such_key: [1, 2]\n", "vary.belts.no_such_key"),
    "unknown top key": ("colour: red\n", "colour"),
    "empty range": ("vary:\n  belts.input_nominal_in_s: [3.0, 2.0]\n", "empty range"),
    "unknown constraint measure": ("constraints: ['lost_parts <= 1']\n", "constraints[0]"),
    "objective no run reports": ("objectives: [{measure: happiness, goal: maximize}]\n",
                                 "objectives[0].measure"),
    "objective only the other policy reports": (
        "objectives: [{measure: thesis_slack_s, goal: minimize}]\n", "objectives[0].measure"),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_study_files_get_one_line_and_exit_2(tmp_path: Path, capsys, case: str) -> None:
    extra, where = BAD[case]
    good = {"base": f"base: {BASE}\n", "vary": "vary:\n  belts.input_nominal_in_s: [2.0, 3.0]\n",
            "objectives": "objectives: [{measure: parts_missed, goal: minimize}]\n",
            "trials": "trials: 2\n"}
    head = extra.split(":")[0]
    text = "".join(v for k, v in good.items() if k != head) + extra
    path = _study(tmp_path, text)
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and where in err[0], err
    assert not out.exists()



@pytest.mark.usefixtures("unlaid")
def test_a_killed_optimize_ends_as_every_command_does(tmp_path: Path, monkeypatch,
                                                      capsys) -> None:
    """kill (SIGTERM) during the trials: 143 and ``cell: terminated`` last (it said 130 and
    ``cell: interrupted``, its own handler's), the finished trial kept for --resume."""
    import os

    import cell.experiments.optimize as optimize

    real, calls = optimize.replicate, []

    def replicate(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            os.kill(os.getpid(), signal.SIGTERM)
        return real(*args, **kwargs)

    monkeypatch.setattr(optimize, "replicate", replicate)
    path = _study(tmp_path, FIXED.replace("TRIALS", "4"))
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out)]) == 143
    assert capsys.readouterr().err.splitlines()[-1] == "cell: terminated"
    assert _completed(out / "study.db") == 1 and not (out / "trials.csv").exists()


SMALL = f"""base: {BASE}
set: {{run.parts: 20}}
vary:
  belts.input_nominal_in_s: [2.0, 3.0]
objectives: [{{measure: parts_missed, goal: minimize}}]
trials: 1
replications: 1
"""


def _sqlite(path: Path, *statements: str) -> None:
    import sqlite3

    con = sqlite3.connect(path)
    for s in statements:
        con.execute(s)
    con.commit()
    con.close()


def _optuna_study(path: Path, name: str, fingerprint: str | None = None) -> None:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    o = optuna.create_study(study_name=name, storage=f"sqlite:///{path}")
    if fingerprint is not None:
        o.set_user_attr("fingerprint", fingerprint)


#: What ``DIR/study.db`` is, made independently of cell (random bytes, a directory, another
#: program's SQLite database, a damaged one, another Optuna study, this study's name from
#: another study file): each refused in one line naming study.db, exit 2, nothing written.
STORES = {
    "random bytes": lambda p: p.write_bytes(bytes(range(256)) * 40),
    "empty file": lambda p: p.write_bytes(b""),
    "directory": lambda p: (p.mkdir(), (p / "keep.txt").write_text("mine")),
    "another program's SQLite": lambda p: _sqlite(
        p, "CREATE TABLE people (name TEXT, age INTEGER)", "INSERT INTO people VALUES ('ann', 41)"),
    "damaged SQLite": lambda p: p.write_bytes(b"SQLite format 3\x00" + bytes(4080)),
    "another study": lambda p: _optuna_study(p, "someone-elses"),
    "this name, another study file": lambda p: _optuna_study(p, "study", "0" * 64),
}


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("case", list(STORES), ids=list(STORES))
def test_a_foreign_or_damaged_study_db_is_refused_and_left_as_it_was(tmp_path: Path, capsys,
                                                                      case: str) -> None:
    path = _study(tmp_path, SMALL)
    out = tmp_path / "out"
    out.mkdir()
    STORES[case](out / "study.db")
    (out / "trials.csv").write_text("trial,parts_missed\n0,3\n")  # the study's own results
    before = _snapshot(out)
    assert main(["optimize", str(path), "--out", str(out), "--resume"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(out) in err[0] and "study.db" in err[0], err
    assert _snapshot(out) == before


def test_an_unreachable_scheduler_is_one_line_before_anything_is_written(tmp_path: Path,
                                                                         capsys) -> None:
    import socket

    with socket.socket() as s:  # a port nothing listens on (bound, never listening)
        s.bind(("127.0.0.1", 0))
        address = f"tcp://127.0.0.1:{s.getsockname()[1]}"
        path = _study(tmp_path, SMALL)
        out = tmp_path / "out"
        assert main(["optimize", str(path), "--out", str(out), "--scheduler", address]) == 2
    err = [x for x in capsys.readouterr().err.strip().splitlines() if not x.startswith("connecting")]
    assert len(err) == 1 and f"--scheduler {address}" in err[0], err
    assert not out.exists()


@pytest.mark.parametrize("measure", ["cost_per_good_part", "energy_per_good_part_wh"])
def test_money_and_energy_are_objectives_where_the_base_gives_their_section(tmp_path, measure):
    """A study may minimise the cost or energy per good part (summary.csv's optional columns)
    when its base scenario has the ``costs:`` / ``energy:`` section that reports it; without
    it the objective is refused naming the key and the measure, before any work."""
    from cell.plumbing.errors import ScenarioError

    (tmp_path / "money.yaml").write_text(
        "run: {parts: 20}\nenergy: {power_w: {robot: {busy: 120}}}\n"
        "costs: {part_value: 12.0, energy_per_kwh: 0.2}\n")
    (tmp_path / "plain.yaml").write_text("run: {parts: 20}\n")
    for base in ("money", "plain"):
        (tmp_path / f"{base}_study.yaml").write_text(
            f"base: {base}.yaml\nvary:\n  belts.input_nominal_in_s: {{low: 2.0, high: 3.0}}\n"
            f"objectives:\n  - {{measure: {measure}, goal: minimize}}\ntrials: 2\nreplications: 2\n")
    study = load_study(tmp_path / "money_study.yaml")
    assert study.settings.objectives[0].measure == measure
    with pytest.raises(ScenarioError) as refused:
        load_study(tmp_path / "plain_study.yaml")
    assert (refused.value.key, refused.value.value) == ("objectives[0].measure", measure)
    assert ("costs" if measure.startswith("cost") else "energy") in refused.value.why


@pytest.mark.usefixtures("unlaid")
def test_an_optimisation_over_places_and_a_station_s_key(tmp_path: Path) -> None:
    """A buffer's places and a station's keys (by its name) are varied like any other key
    (docs/layout.md): each trial's row holds the values it ran, whole places whole, and the
    best trial has a buffer (Poisson arrivals at about the robot's cycle: without one a
    single robot loses about half the parts it is offered)."""
    study = tmp_path / "study.yaml"
    study.write_text(
        "name: places\nbase: baseline\n"
        "set: {run.parts: 80, controller.policy: non-adaptive,"
        " arrivals: {distribution: expon, params: {loc: 0.0, scale: 22.0}},"
        " stations: [{name: catcher, placement: downstream, offset_in: 40,"
        " controller: {policy: non-adaptive}}]}\n"
        "vary: {buffer.places: {low: 0, high: 4, step: 1},"
        " stations.catcher.offset_in: {low: 10.0, high: 60.0, step: 10.0}}\n"
        "objectives: [{measure: parts_missed, goal: minimize}]\n"
        "trials: 4\nreplications: 2\nseed: 3\n", encoding="utf-8")
    assert main(["optimize", str(study), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    trials = pd.read_csv(tmp_path / "out" / "trials.csv")
    assert set(trials["buffer.places"]) <= {0, 1, 2, 3, 4}
    assert set(trials["stations.catcher.offset_in"]) <= {10.0, 20.0, 30.0, 40.0, 50.0, 60.0}
    assert (trials["buffer.places"] % 1 == 0).all()
    assert trials.loc[trials["parts_missed"].idxmin(), "buffer.places"] > 0
