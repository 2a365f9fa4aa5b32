"""The sweep runner on a dask cluster and from the command line: the same numbers as local
workers, one clear line for an unreachable scheduler, warnings and the report."""

from __future__ import annotations

import numpy as np
import pytest

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.plumbing.errors import CellError
from tests.prose import in_order

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")

TABLE_7_1_CYCLES = [22.5872, 22.0, 21.5, 21.0, 20.5, 20.0907]


# --------------------------------------------------------------------------- dask
def test_dask_cluster_gives_the_same_numbers_as_local_workers(sweeps, tmp_path):
    distributed = pytest.importorskip("distributed")
    sweep = load_sweep(sweeps.write(tmp_path))
    run_sweep(sweep, tmp_path / "local", workers=2, replicate=sweeps.bookkeeping, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        outcome = run_sweep(sweep, tmp_path / "dask", scheduler=cluster.scheduler_address,
                            replicate=sweeps.bookkeeping, progress=False)
    assert outcome.tasks_run == 9
    assert ((tmp_path / "dask" / "replications.csv").read_bytes()
            == (tmp_path / "local" / "replications.csv").read_bytes())


def test_unreachable_scheduler_is_one_clear_error_and_no_output(sweeps, tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    sweep = load_sweep(sweeps.write(tmp_path))
    with pytest.raises(CellError, match="nothing listens there"):
        run_sweep(sweep, tmp_path / "o", scheduler="tcp://127.0.0.1:9", progress=False,
                  replicate=sweeps.first_draw)
    assert not (tmp_path / "o").exists()


def test_cli_says_it_is_reaching_a_scheduler_before_it_waits(sweeps, tmp_path, monkeypatch,
                                                             capsys):
    pytest.importorskip("distributed")
    path = sweeps.write(tmp_path)
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--scheduler",
                 "tcp://127.0.0.1:9"])
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and not (tmp_path / "o").exists()
    assert in_order(err[0], "connecting", "scheduler at tcp://127.0.0.1:9", "after 10 s")
    assert "(connection refused)" in err[-1] and len(err) == 2


# --------------------------------------------------------------------------- command line
def test_cli_writes_replications_and_report(sweeps, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    path = sweeps.write(tmp_path, set={"run.parts": 500})  # the thesis's cell: Table 7.1 too
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "o" / "replications.csv").is_file()
    assert (tmp_path / "rep" / "table_7_1.csv").is_file()
    assert (tmp_path / "rep" / "table_7_1.md").is_file()


def test_a_sweep_and_a_run_say_overload_in_the_same_words(sweeps, tmp_path):
    """The sweep's line and cell run's line differ only in what opens them and in the run's
    own times, which the run's gives."""
    from cell.experiments.sweep.spec import overload_warning
    from cell.reporting.run_summary import warnings
    from cell.sim.assembly import assemble

    arrivals = {"distribution": "gamma", "mean_s": 15.0, "cv": 0.3}
    sweep = load_sweep(sweeps.write(tmp_path, policies=["adaptive"],
                                    set={"run.parts": 20, "arrivals": arrivals,
                                         "controller.nominal_cycle_s": None}))
    k = assemble(sweep.points[0].scenario).k
    ran = warnings(k)[0]
    swept = overload_warning(sweep)
    assert ran.startswith(f"offered load {k.fastest_cycle_s / 15:.3f}: ")
    assert swept.startswith("1 of 1 points have ")
    assert in_order(ran, f"fastest cycle ({k.fastest_cycle_s:.2f} s)", "inter-arrival", "(15.00 s);")
    said = ran.split("; ")[-1]  # what follows: the same words in both
    assert "every policy" in said and swept.endswith(f"; {said}")
    assert in_order(swept, "fastest cycle is not shorter", "inter-arrival time there;")


def test_cli_warns_of_points_that_cannot_keep_up(sweeps, tmp_path, capsys):
    """Offered load 1 or more at some points: one warning line, as cell run gives for a run."""
    arrivals = {"distribution": "gamma", "mean_s": 22.0, "cv": 0.3}
    path = sweeps.write(tmp_path, policies=["adaptive"], grid={"arrivals.mean_s": [15, 22, 17]},
                        set={"run.parts": 20, "arrivals": arrivals,
                             "controller.nominal_cycle_s": None})
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warned) == 1 and in_order(warned[0], "2 of 3 points", "offered load 1 or more")
    assert "at arrivals.mean_s 15" in warned[0]  # the worst: fastest cycle 18.08 s over 15 s
    quiet = sweeps.write(tmp_path, policies=["adaptive"], grid={"arrivals.mean_s": [22, 25]},
                         set={"run.parts": 20, "arrivals": arrivals,
                              "controller.nominal_cycle_s": None})
    assert main(["sweep", str(quiet), "--out", str(tmp_path / "q"), "--workers", "1"]) == 0
    assert "offered load" not in capsys.readouterr().err


def test_cli_reports_any_sweep(sweeps, tmp_path, monkeypatch, capsys):
    """A sweep that is not Table 7.1's gets the general report, without Table 7.1."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    path = sweeps.write(tmp_path, grid={"belts.output_nominal_in_s": [2.0, 2.5]})
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0, capsys.readouterr().err
    names = {p.name for p in (tmp_path / "rep").iterdir()}
    assert {"report.md", "summary.csv", "differences.csv"} <= names
    assert "table_7_1.md" not in names


def spawning(scenario, seed) -> dict:
    """A replication that spawns from its stream (which mutates the SeedSequence)."""
    return {"u": np.random.default_rng(seed.spawn(1)[0]).random()}


def test_a_replication_that_spawns_cannot_break_common_random_numbers(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path, batch=6))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=spawning,
                      progress=False).replications
    per_point = frame.pivot(index="replication", columns=["policy", "point"], values="u")
    assert (per_point.nunique(axis=1) == 1).all()
