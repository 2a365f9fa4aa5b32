"""The sweep runner: sweep files, streams, workers, resume, dask (thesis §6.3; docs/accounting.md).

The runner takes the replication as a function, so these tests drive it with
small deterministic stand-ins that draw from the stream they are given.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.plumbing.errors import CellError, ScenarioError
from cell.scenario import catalog
from cell.scenario.schema import load_scenario

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")

TABLE_7_1_CYCLES = [22.5872, 22.0, 21.5, 21.0, 20.5, 20.0907]


# --------------------------------------------------------------------------- the sweep file
def test_table_7_1_sweep_file_has_the_thesis_rows():
    sweep = load_sweep(catalog.BUILT_IN / "table_7_1.yaml")
    na = [p for p in sweep.points if p.policy == "non-adaptive"]
    assert [p.scenario.controller.ideal_cycle_s for p in na] == TABLE_7_1_CYCLES
    ad = [p for p in sweep.points if p.policy == "adaptive"]
    assert len(ad) == 1 and ad[0].scenario.controller.ideal_cycle_s is None
    assert all(p.scenario.run.parts == 500 for p in sweep.points)  # §6.3
    assert sweep.replications >= 200


def test_grid_is_the_product_of_shared_and_per_policy_keys(sweeps, tmp_path):
    path = sweeps.write(tmp_path, grid={"belts.output_nominal_in_s": [2.0, 2.5]})
    sweep = load_sweep(path)
    assert sweep.keys == ("belts.output_nominal_in_s", "controller.ideal_cycle_s")
    na = [dict(p.values) for p in sweep.points if p.policy == "non-adaptive"]
    assert len(na) == 4 and {"belts.output_nominal_in_s": 2.5,
                             "controller.ideal_cycle_s": 21.0} in na
    assert [p.scenario.belts.output_nominal_in_s for p in sweep.points
            if p.policy == "adaptive"] == [2.0, 2.5]


BAD = [
    ({"grid": {"controller.idle_cycle_s": [20.0]}}, "controller.idle_cycle_s", "unknown key"),
    ({"grid": {}, "policies": ["non-adaptive"]}, "grid", "empty grid"),
    ({"replications": 0}, "replications", "at least 1"),
    ({"policies": {"non-adaptive": {"controller.ideal_cycle_s": []}}},
     "controller.ideal_cycle_s", "empty list"),
    ({"policies": {"non-adaptive": {"controller.ideal_cycle_s": [22.0, -1.0]}}},
     "controller.ideal_cycle_s", "greater than 0"),
    ({"policies": {"adaptive": {"controller.ideal_cycle_s": [22.0]}}},
     "controller.ideal_cycle_s", "adaptive policy runs at the nominal cycle"),
    ({"policies": {"fast": {}}}, "policies", "must be one of"),
    ({"grid": {"run.seed": [1, 2]}}, "run.seed", "cannot be varied"),
    ({"replicates": 5}, "replicates", "unknown key"),
    ({"seed": -3}, "seed", "at least 0"),
    ({"set": {"run.part": 10}}, "run.part", "unknown key"),
    ({"base": "nowhere.yaml"}, "base", "no such scenario file"),
    ({"base": " "}, "base", "name the base scenario"),
    ({"replications": {"precision": 0, "measure": "parts_missed", "max": 50}},
     "replications.precision", "above 0"),
    ({"replications": {"precision": 0.01, "measure": "parts_mised", "max": 50}},
     "replications.measure", "numeric column"),
    ({"replications": {"precision": 0.01, "measure": "parts_missed", "min": 10, "max": 5}},
     "replications.max", "at least 10"),
    ({"replications": {"precision": 0.01, "measure": "parts_missed", "max": 50,
                       "confidence": 95}}, "replications.confidence", "between 0 and 1"),
    ({"replications": {"precision": 0.01, "measure": "parts_missed", "maximum": 50}},
     "replications.maximum", "unknown key"),
    ({"baseline": {"policy": "fast"}}, "baseline.policy", "not a policy of this sweep"),
    ({"baseline": {"controller.ideal_cycle_s": 19.0}}, "baseline.controller.ideal_cycle_s",
     "not among the grid's values"),
    ({"baseline": {"belts.output_nominal_in_s": 2.0}}, "baseline.belts.output_nominal_in_s",
     "not a key this sweep varies"),
    ({"baseline": {"policy": "adaptive", "controller.ideal_cycle_s": 22.0}},
     "baseline.controller.ideal_cycle_s", "does not vary this key"),
    ({"baseline": {"policy": "non-adaptive"}}, "baseline", "name the value of "
     "controller.ideal_cycle_s"),
    ({"baseline": [1, 2]}, "baseline", "must name a point"),
    ({"replications": 20.0}, "replications = 20.0", "at least 1; write 20"),
    ({"replications": 2.5}, "replications = 2.5", "at least 1"),
    ({"replications": {"precision": 0.01, "measure": "parts_missed", "min": 5.0, "max": 50}},
     "replications.min = 5.0", "at least 2; write 5"),
    ({"seed": 7.0}, "seed = 7.0", "at least 0; write 7"),
]


@pytest.mark.parametrize(("fields", "key", "why"), BAD)
def test_bad_sweep_file_one_line_exit_2_no_output(sweeps, tmp_path, capsys, fields, key, why):
    path = sweeps.write(tmp_path, **fields)
    out = tmp_path / "out"
    report = tmp_path / "rep"
    code = main(["sweep", str(path), "--out", str(out), "--workers", "1",
                 "--report", str(report)])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert key in err and why in err
    assert "sweep.yaml" in err or "nowhere.yaml" in err
    assert not out.exists() and not report.exists()


def test_base_by_a_built_in_name(sweeps, tmp_path):
    """``base: baseline`` (or baseline.yaml) with no such file beside the sweep file is the
    built-in scenario, as ``cell run baseline`` is; a file of that name beside it wins."""
    for name in ("baseline", "baseline.yaml"):
        sweep = load_sweep(sweeps.write(tmp_path, base=name))
        assert sweep.points[0].scenario.arrivals == load_scenario("baseline").arrivals
    (tmp_path / "baseline.yaml").write_text("name: mine\narrivals: {mean_s: 30, cv: 0.2, "
                                            "distribution: gamma}\n")
    sweep = load_sweep(sweeps.write(tmp_path, base="baseline.yaml", policies=["adaptive"]))
    assert sweep.points[0].scenario.arrivals.mean_s == 30


@pytest.mark.parametrize("name", ["baseline", "baseline.yaml", "./non_adaptive", "mine", "mine.yaml",
                                  "nowhere.yaml"])
def test_base_is_found_as_cell_run_finds_its_scenario(sweeps, tmp_path, monkeypatch, name):
    """The sweep file's folder is to ``base`` what the working folder is to cell run's
    SCENARIO (:func:`cell.scenario.catalog.resolve`): what is there by that name wins, a folder too
    (refused: not a scenario file), else a built-in one by name."""
    (tmp_path / "mine.yaml").write_text("name: mine\n")
    (tmp_path / "baseline").mkdir()

    def found(load) -> str:  # noqa: ANN001
        try:
            return str(Path(load()).resolve())
        except ScenarioError as exc:
            return next(w for w in ("no such scenario file", "is a directory") if w in str(exc))

    path = sweeps.write(tmp_path, base=name)
    swept = found(lambda: load_sweep(path).base.source)
    monkeypatch.chdir(tmp_path)
    assert swept == found(lambda: load_scenario(name).source)


def test_a_file_the_sweep_names_is_found_from_the_sweep_s_folder(sweeps, tmp_path):
    """A trace set by the sweep file is beside the sweep file, even over a built-in base."""
    (tmp_path / "log.csv").write_text("interarrival_s\n20\n25\n")
    sweep = load_sweep(sweeps.write(tmp_path, base="baseline", policies=["adaptive"],
                                    set={"run.parts": 5, "arrivals.trace_csv": "log.csv"}))
    s = sweep.points[0].scenario
    assert s.base_dir / s.arrivals.trace_csv == tmp_path / "log.csv"


def test_bad_value_error_names_file_key_and_value(sweeps, tmp_path):
    path = sweeps.write(tmp_path, policies={"non-adaptive": {"controller.ideal_cycle_s":
                                                            [22.0, "fast"]}})
    with pytest.raises(ScenarioError) as exc:
        load_sweep(path)
    assert (exc.value.file, exc.value.key, exc.value.value) == (
        str(path), "controller.ideal_cycle_s", "fast")


# --------------------------------------------------------------------------- streams
def test_replication_r_uses_spawned_stream_r_at_every_point(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=sweeps.first_draw,
                      progress=False).replications
    children = np.random.SeedSequence(7).spawn(6)
    expected = [np.random.default_rng(children[r]).random() for r in range(6)]
    assert len(frame) == 3 * 6
    for (_policy, _point), group in frame.groupby(["policy", "point"]):
        # the same arrivals at every grid point and for both policies (CRN)
        np.testing.assert_allclose(group.sort_values("replication")["u"], expected, rtol=1e-9)
    assert sorted(set(frame["cycle"])) == [-1.0, 21.0, 22.0]
    assert set(frame["parts"]) == {20}  # the sweep's 'set' reached every run


def test_rows_sorted_and_labelled(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=sweeps.first_draw,
                      progress=False).replications
    assert list(frame.columns[:5]) == ["policy", "point", "controller.ideal_cycle_s", "seed",
                                       "replication"]
    assert list(frame["policy"]) == ["non-adaptive"] * 12 + ["adaptive"] * 6
    assert list(frame["replication"]) == list(range(6)) * 3
    assert set(frame["seed"]) == {7}
    # not varied for adaptive, and this stand-in reports no effective cycle: empty
    assert math.isnan(frame["controller.ideal_cycle_s"].iloc[-1])


def test_points_that_do_not_vary_a_key_hold_their_effective_value(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=sweeps.bookkeeping,
                      progress=False).replications
    by_policy = frame.groupby(["policy", "controller.ideal_cycle_s"]).size()
    assert by_policy.to_dict() == {("adaptive", 22.5872): 6, ("non-adaptive", 21.0): 6,
                                   ("non-adaptive", 22.0): 6}


def test_workers_1_and_2_give_byte_identical_replications(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path, batch=1))
    run_sweep(sweep, tmp_path / "w1", workers=1, replicate=sweeps.bookkeeping, progress=False)
    run_sweep(sweep, tmp_path / "w2", workers=2, replicate=sweeps.bookkeeping, progress=False)
    one = (tmp_path / "w1" / "replications.csv").read_bytes()
    assert one == (tmp_path / "w2" / "replications.csv").read_bytes()
    assert one.count(b"\n") == 1 + 18


# --------------------------------------------------------------------------- resume
def test_interrupted_then_resumed_equals_uninterrupted(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path))  # 3 points x 6 reps, 9 tasks of 2
    run_sweep(sweep, tmp_path / "whole", workers=1, replicate=sweeps.bookkeeping, progress=False)
    killer = sweeps.Interrupt(after=9)  # dies inside the 5th task: 4 tasks (8 reps) on disk
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, tmp_path / "cut", workers=1, replicate=killer, progress=False)
    assert len(list((tmp_path / "cut" / "tasks").glob("task-*.csv"))) == 4
    assert not (tmp_path / "cut" / "replications.csv").exists()
    counter = sweeps.Interrupt(after=10**9)
    outcome = run_sweep(sweep, tmp_path / "cut", workers=1, resume=True, replicate=counter,
                        progress=False)
    assert (outcome.tasks_run, outcome.tasks_reused, counter.calls) == (5, 4, 10)
    assert ((tmp_path / "cut" / "replications.csv").read_bytes()
            == (tmp_path / "whole" / "replications.csv").read_bytes())


def test_resume_of_a_finished_sweep_runs_nothing(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path))
    run_sweep(sweep, tmp_path / "o", workers=1, replicate=sweeps.first_draw, progress=False)
    counter = sweeps.Interrupt(after=10**9)
    outcome = run_sweep(sweep, tmp_path / "o", workers=1, resume=True,
                        replicate=counter, progress=False)
    assert (outcome.tasks_run, counter.calls) == (0, 0)


def test_resume_refuses_a_different_sweep(sweeps, tmp_path):
    run_sweep(load_sweep(sweeps.write(tmp_path)), tmp_path / "o", workers=1,
              replicate=sweeps.first_draw, progress=False)
    other = load_sweep(sweeps.write(tmp_path, seed=8))
    with pytest.raises(CellError, match=r"\(--resume\): holds the results of this sweep "
                       r"\(sweep\) as it was before .*sweep.yaml changed: choose another "
                       "--out or remove it$"):
        run_sweep(other, tmp_path / "o", workers=1, resume=True, replicate=sweeps.first_draw,
                  progress=False)


def test_a_fresh_run_of_an_edited_sweep_keeps_the_old_results(sweeps, tmp_path):
    """Without --resume, results of the sweep as it was are not deleted: refused first."""
    run_sweep(load_sweep(sweeps.write(tmp_path)), tmp_path / "o", workers=1,
              replicate=sweeps.first_draw, progress=False)
    before = sorted((tmp_path / "o").rglob("*"))
    smaller = load_sweep(sweeps.write(tmp_path, replications=2))
    with pytest.raises(CellError, match="holds this sweep's results at replications: 6: add "
                                        "--resume to reuse those that fit replications: 2"):
        run_sweep(smaller, tmp_path / "o", workers=1, replicate=sweeps.first_draw,
                  progress=False)
    assert sorted((tmp_path / "o").rglob("*")) == before
    assert len(list((tmp_path / "o" / "tasks").glob("task-*.csv"))) == 9


# --------------------------------------------------------------------------- the real cell
def test_real_simulation_same_numbers_locally_and_on_dask(sweeps, tmp_path):
    """The cell itself, a few short runs: in-process, 2 workers and dask agree."""
    pytest.importorskip("cell.sim.simulation")
    distributed = pytest.importorskip("distributed")
    sweep = load_sweep(sweeps.write(tmp_path, replications=2, batch=1))
    run_sweep(sweep, tmp_path / "w1", workers=1, progress=False)
    run_sweep(sweep, tmp_path / "w2", workers=2, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        run_sweep(sweep, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False)
    one = (tmp_path / "w1" / "replications.csv").read_bytes()
    assert one == (tmp_path / "w2" / "replications.csv").read_bytes()
    assert one == (tmp_path / "dask" / "replications.csv").read_bytes()


def assembling_each_time(scenario, seed) -> dict:
    """The default replication as it was: the cell assembled for every run."""
    from cell.sim.simulation import simulate

    return simulate(scenario, seed=seed, keep_parts=False, keep_belts=False).summary.as_dict()


def test_real_simulation_assembles_a_cell_once_a_point_and_gives_the_same_bytes(
        sweeps, tmp_path, monkeypatch):
    import cell.sim.assembly

    sweep = load_sweep(sweeps.write(tmp_path, replications=3, batch=2))  # 2 tasks a point
    run_sweep(sweep, tmp_path / "each", workers=1, replicate=assembling_each_time,
              progress=False)
    built, assemble = [], cell.sim.assembly.assemble
    monkeypatch.setattr(cell.sim.assembly, "assemble", lambda s: built.append(s) or assemble(s))
    run_sweep(sweep, tmp_path / "w1", workers=1, progress=False)
    monkeypatch.undo()
    assert len(built) == 3 and all(b is p.scenario for b, p in zip(built, sweep.points))
    run_sweep(sweep, tmp_path / "w2", workers=2, progress=False)
    each = (tmp_path / "each" / "replications.csv").read_bytes()
    assert each.count(b"\n") == 1 + 9
    assert each == (tmp_path / "w1" / "replications.csv").read_bytes()
    assert each == (tmp_path / "w2" / "replications.csv").read_bytes()


def test_real_simulation_both_policies_see_the_same_parts(sweeps, tmp_path):
    pytest.importorskip("cell.sim.simulation")
    sweep = load_sweep(sweeps.write(tmp_path, replications=2, set={"run.parts": 30}))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, progress=False).replications
    assert set(frame["parts_arrived"]) == {30}
    # the adaptive policy loses nothing on the same arrivals (§7.2) ...
    assert (frame.loc[frame["policy"] == "adaptive", "parts_missed"] == 0).all()
    # ... and replication r carries the same stream label at every point (CRN)
    seeds = frame.pivot(index="replication", columns=["policy", "point"], values="seed")
    assert (seeds.nunique(axis=1) == 1).all()


def test_zero_workers_is_one_clear_error_and_no_output(sweeps, tmp_path, capsys):
    code = main(["sweep", str(sweeps.write(tmp_path)), "--out", str(tmp_path / "o"),
                 "--workers", "0"])
    assert code == 2 and "--workers 0" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_a_section_in_the_grid_merges_and_keeps_each_policy(sweeps, tmp_path):
    """A whole section given as a grid value merges into it: the sweep's policy stays."""
    path = sweeps.write(tmp_path, grid={"controller": [{"nominal_cycle_s": 22.5872}]},
                       policies=["non-adaptive", "adaptive"])
    sweep = load_sweep(path)
    assert [p.scenario.controller.policy for p in sweep.points] == ["non-adaptive", "adaptive"]
    bad = sweeps.write(tmp_path, grid={"controller": [{"policy": "adaptive"}]})
    with pytest.raises(ScenarioError, match="cannot be varied"):
        load_sweep(bad)


def test_a_grid_over_a_distribution_parameter(sweeps, tmp_path):
    path = sweeps.write(tmp_path, grid={"arrivals.params.loc": [16.0, 17.6019]},
                       policies=["adaptive"])
    sweep = load_sweep(path)
    assert [p.scenario.arrivals.params["loc"] for p in sweep.points] == [16.0, 17.6019]
    assert all(p.scenario.arrivals.params["scale"] == 5.4342 for p in sweep.points)


def test_an_interrupted_sweep_says_how_to_go_on(tmp_path, capsys):
    """Ctrl-C in the middle of ``cell sweep``: exit 130, one line naming what is kept and
    --resume; the same command with --resume then reuses those tasks (run in this process:
    the resume is not about a process, the Ctrl-C is)."""
    import signal
    import subprocess
    import sys

    # a few seconds of work in small tasks (Table 7.1's sweep did the same in a minute)
    sweep = tmp_path / "s.yaml"
    sweep.write_text("base: baseline\nset: {run.parts: 100}\npolicies: [non-adaptive, adaptive]\n"
                     "replications: 100\nbatch: 5\nseed: 7\n")
    command = [sys.executable, "-m", "cell", "sweep", str(sweep), "--out", str(tmp_path / "out"),
               "--workers", "1"]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    assert proc.stderr is not None
    for line in proc.stderr:  # progress lines come on stderr when it is not a terminal
        if "replications (" in line:
            proc.send_signal(signal.SIGINT)
            break
    err = proc.communicate()[1]  # the rest, then closed and waited for
    assert proc.returncode == 130, err
    hint = next(line for line in err.splitlines() if line.startswith("cell sweep: stopped"))
    kept = int(hint.split("; ")[1].split()[0])
    assert kept > 0 and "--resume" in hint
    assert main([*command[3:], "--resume"]) == 0
    assert f"{kept} reused)" in capsys.readouterr().out


def test_a_grid_over_buffer_places_runs_each_layout(tmp_path):
    """A buffer's places are a key like any other (docs/layout.md): a grid over them runs each
    layout, and the fixed-cycle robot loses fewer parts with more places (a queue with more
    waiting room loses less: M/D/1/K's loss falls with K), with the line's totals in the rows."""
    path = tmp_path / "places.yaml"
    path.write_text(
        "name: places\nbase: baseline\n"
        "set: {run.parts: 300,"
        " arrivals: {distribution: expon, params: {loc: 0.0, scale: 22.0}}}\n"
        "grid: {buffer.places: [0, 1, 3]}\npolicies: [non-adaptive]\nreplications: 2\nseed: 5\n",
        encoding="utf-8")
    frame = run_sweep(load_sweep(path), tmp_path / "out", workers=1, progress=False).replications
    lost = frame.groupby("buffer.places")["parts_missed"].mean()
    assert list(lost.index) == [0, 1, 3]
    assert lost[0] > lost[1] > lost[3]
    assert (frame["parts_delivered"] + frame["parts_missed"] == 300).all()
