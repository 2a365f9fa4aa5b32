"""The sweep runner: sweep files, streams, workers, resume, dask (thesis §6.3; docs/accounting.md).

The runner takes the replication as a function, so these tests drive it with
small deterministic stand-ins that draw from the stream they are given.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.cli import main
from cell.errors import CellError, ScenarioError
from cell.sweep import load_sweep, run_sweep

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"

# Table 7.1, column 1 (thesis §7.2; docs/accounting.md).
TABLE_7_1_CYCLES = [22.5872, 22.0, 21.5, 21.0, 20.5, 20.0907]


def weibull_interarrivals(rng: np.random.Generator, n: int) -> np.ndarray:
    """Eq. 6.9 by inverse cdf: T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038 (docs/model.md)."""
    return 17.6019 + 5.4342 * (-np.log1p(-rng.random(n))) ** 0.2038


def spec_bookkeeping(scenario, seed) -> dict:
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
    doc = {"base": str(SCENARIOS / "baseline.yaml"), "set": {"run.parts": 20},
           "policies": {"non-adaptive": {"controller.ideal_cycle_s": [22.0, 21.0]},
                        "adaptive": {}},
           "replications": 6, "seed": 7, "batch": 2}
    doc.update(fields)
    doc = {k: v for k, v in doc.items() if v is not None}
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


# --------------------------------------------------------------------------- the sweep file
def test_table_7_1_sweep_file_has_the_thesis_rows():
    sweep = load_sweep(SCENARIOS / "table_7_1.yaml")
    na = [p for p in sweep.points if p.policy == "non-adaptive"]
    assert [p.scenario.controller.ideal_cycle_s for p in na] == TABLE_7_1_CYCLES
    ad = [p for p in sweep.points if p.policy == "adaptive"]
    assert len(ad) == 1 and ad[0].scenario.controller.ideal_cycle_s is None
    assert all(p.scenario.run.parts == 500 for p in sweep.points)  # §6.3
    assert sweep.replications >= 200


def test_grid_is_the_product_of_shared_and_per_policy_keys(tmp_path):
    path = write_sweep(tmp_path, grid={"belts.output_nominal_in_s": [2.0, 2.5]})
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
]


@pytest.mark.parametrize(("fields", "key", "why"), BAD)
def test_bad_sweep_file_one_line_exit_2_no_output(tmp_path, capsys, fields, key, why):
    path = write_sweep(tmp_path, **fields)
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


def test_bad_value_error_names_file_key_and_value(tmp_path):
    path = write_sweep(tmp_path, policies={"non-adaptive": {"controller.ideal_cycle_s":
                                                            [22.0, "fast"]}})
    with pytest.raises(ScenarioError) as exc:
        load_sweep(path)
    assert (exc.value.file, exc.value.key, exc.value.value) == (
        str(path), "controller.ideal_cycle_s", "fast")


# --------------------------------------------------------------------------- streams
def test_replication_r_uses_spawned_stream_r_at_every_point(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=first_draw,
                      progress=False).replications
    children = np.random.SeedSequence(7).spawn(6)
    expected = [np.random.default_rng(children[r]).random() for r in range(6)]
    assert len(frame) == 3 * 6
    for (_policy, _point), group in frame.groupby(["policy", "point"]):
        # the same arrivals at every grid point and for both policies (CRN)
        np.testing.assert_allclose(group.sort_values("replication")["u"], expected, rtol=1e-9)
    assert sorted(set(frame["cycle"])) == [-1.0, 21.0, 22.0]
    assert set(frame["parts"]) == {20}  # the sweep's 'set' reached every run


def test_rows_sorted_and_labelled(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=first_draw,
                      progress=False).replications
    assert list(frame.columns[:5]) == ["policy", "point", "controller.ideal_cycle_s", "seed",
                                       "replication"]
    assert list(frame["policy"]) == ["non-adaptive"] * 12 + ["adaptive"] * 6
    assert list(frame["replication"]) == list(range(6)) * 3
    assert set(frame["seed"]) == {7}
    # not varied for adaptive, and this stand-in reports no effective cycle: empty
    assert math.isnan(frame["controller.ideal_cycle_s"].iloc[-1])


def test_points_that_do_not_vary_a_key_hold_their_effective_value(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    frame = run_sweep(sweep, tmp_path / "out", workers=1, replicate=spec_bookkeeping,
                      progress=False).replications
    by_policy = frame.groupby(["policy", "controller.ideal_cycle_s"]).size()
    assert by_policy.to_dict() == {("adaptive", 22.5872): 6, ("non-adaptive", 21.0): 6,
                                   ("non-adaptive", 22.0): 6}


def test_workers_1_and_2_give_byte_identical_replications(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path, batch=1))
    run_sweep(sweep, tmp_path / "w1", workers=1, replicate=spec_bookkeeping, progress=False)
    run_sweep(sweep, tmp_path / "w2", workers=2, replicate=spec_bookkeeping, progress=False)
    one = (tmp_path / "w1" / "replications.csv").read_bytes()
    assert one == (tmp_path / "w2" / "replications.csv").read_bytes()
    assert one.count(b"\n") == 1 + 18


# --------------------------------------------------------------------------- resume
class Interrupt:
    """A replication that is 'killed' (KeyboardInterrupt) after ``after`` runs of ``of``."""

    def __init__(self, after: int, of=spec_bookkeeping):
        self.after, self.calls, self.of = after, 0, of

    def __call__(self, scenario, seed):
        self.calls += 1
        if self.calls > self.after:
            raise KeyboardInterrupt
        return self.of(scenario, seed)


def test_interrupted_then_resumed_equals_uninterrupted(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))  # 3 points x 6 reps, 9 tasks of 2
    run_sweep(sweep, tmp_path / "whole", workers=1, replicate=spec_bookkeeping, progress=False)
    killer = Interrupt(after=9)  # dies inside the 5th task: 4 tasks (8 reps) on disk
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, tmp_path / "cut", workers=1, replicate=killer, progress=False)
    assert len(list((tmp_path / "cut" / "tasks").glob("task-*.csv"))) == 4
    assert not (tmp_path / "cut" / "replications.csv").exists()
    counter = Interrupt(after=10**9)
    outcome = run_sweep(sweep, tmp_path / "cut", workers=1, resume=True, replicate=counter,
                        progress=False)
    assert (outcome.tasks_run, outcome.tasks_reused, counter.calls) == (5, 4, 10)
    assert ((tmp_path / "cut" / "replications.csv").read_bytes()
            == (tmp_path / "whole" / "replications.csv").read_bytes())


def test_resume_of_a_finished_sweep_runs_nothing(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    run_sweep(sweep, tmp_path / "o", workers=1, replicate=first_draw, progress=False)
    counter = Interrupt(after=10**9)
    outcome = run_sweep(sweep, tmp_path / "o", workers=1, resume=True,
                        replicate=counter, progress=False)
    assert (outcome.tasks_run, counter.calls) == (0, 0)


def test_resume_refuses_a_different_sweep(tmp_path):
    run_sweep(load_sweep(write_sweep(tmp_path)), tmp_path / "o", workers=1,
              replicate=first_draw, progress=False)
    other = load_sweep(write_sweep(tmp_path, seed=8))
    with pytest.raises(CellError, match="different sweep"):
        run_sweep(other, tmp_path / "o", workers=1, resume=True, replicate=first_draw,
                  progress=False)


def test_fresh_run_discards_stale_task_files(tmp_path):
    run_sweep(load_sweep(write_sweep(tmp_path)), tmp_path / "o", workers=1,
              replicate=first_draw, progress=False)
    smaller = load_sweep(write_sweep(tmp_path, replications=2))
    run_sweep(smaller, tmp_path / "o", workers=1, replicate=first_draw, progress=False)
    assert len(list((tmp_path / "o" / "tasks").glob("task-*.csv"))) == 3


# --------------------------------------------------------------------------- dask
def test_dask_cluster_gives_the_same_numbers_as_local_workers(tmp_path):
    distributed = pytest.importorskip("distributed")
    sweep = load_sweep(write_sweep(tmp_path))
    run_sweep(sweep, tmp_path / "local", workers=2, replicate=spec_bookkeeping, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        outcome = run_sweep(sweep, tmp_path / "dask", scheduler=cluster.scheduler_address,
                            replicate=spec_bookkeeping, progress=False)
    assert outcome.tasks_run == 9
    assert ((tmp_path / "dask" / "replications.csv").read_bytes()
            == (tmp_path / "local" / "replications.csv").read_bytes())


def test_unreachable_scheduler_is_one_clear_error_and_no_output(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr("cell.sweep.runner.CONNECT_TIMEOUT", "1s")
    sweep = load_sweep(write_sweep(tmp_path))
    with pytest.raises(CellError, match="cannot reach"):
        run_sweep(sweep, tmp_path / "o", scheduler="tcp://127.0.0.1:9", progress=False,
                  replicate=first_draw)
    assert not (tmp_path / "o").exists()


# --------------------------------------------------------------------------- command line
def test_cli_writes_replications_and_report(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr("cell.sweep.simulate_summary", spec_bookkeeping)
    path = write_sweep(tmp_path)
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "o" / "replications.csv").is_file()
    assert (tmp_path / "rep" / "table_7_1.csv").is_file()
    assert (tmp_path / "rep" / "table_7_1.md").is_file()


def test_cli_reports_any_sweep(tmp_path, monkeypatch, capsys):
    """A sweep that is not Table 7.1's gets the general report, without Table 7.1."""
    monkeypatch.setattr("cell.sweep.simulate_summary", spec_bookkeeping)
    path = write_sweep(tmp_path, grid={"belts.output_nominal_in_s": [2.0, 2.5]})
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0, capsys.readouterr().err
    names = {p.name for p in (tmp_path / "rep").iterdir()}
    assert {"report.md", "summary.csv", "differences.csv"} <= names
    assert "table_7_1.md" not in names


def spawning(scenario, seed) -> dict:
    """A replication that spawns from its stream (which mutates the SeedSequence)."""
    return {"u": np.random.default_rng(seed.spawn(1)[0]).random()}


def test_a_replication_that_spawns_cannot_break_common_random_numbers(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path, batch=6))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=spawning,
                      progress=False).replications
    per_point = frame.pivot(index="replication", columns=["policy", "point"], values="u")
    assert (per_point.nunique(axis=1) == 1).all()


# --------------------------------------------------------------------------- the real cell
def test_real_simulation_same_numbers_locally_and_on_dask(tmp_path):
    """The cell itself, a few short runs: in-process, 2 workers and dask agree."""
    pytest.importorskip("cell.simulation")
    distributed = pytest.importorskip("distributed")
    sweep = load_sweep(write_sweep(tmp_path, replications=2, batch=1))
    run_sweep(sweep, tmp_path / "w1", workers=1, progress=False)
    run_sweep(sweep, tmp_path / "w2", workers=2, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        run_sweep(sweep, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False)
    one = (tmp_path / "w1" / "replications.csv").read_bytes()
    assert one == (tmp_path / "w2" / "replications.csv").read_bytes()
    assert one == (tmp_path / "dask" / "replications.csv").read_bytes()


def test_real_simulation_both_policies_see_the_same_parts(tmp_path):
    pytest.importorskip("cell.simulation")
    sweep = load_sweep(write_sweep(tmp_path, replications=2, set={"run.parts": 30}))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, progress=False).replications
    assert set(frame["parts_arrived"]) == {30}
    # the adaptive policy loses nothing on the same arrivals (§7.2) ...
    assert (frame.loc[frame["policy"] == "adaptive", "parts_missed"] == 0).all()
    # ... and replication r carries the same stream label at every point (CRN)
    seeds = frame.pivot(index="replication", columns=["policy", "point"], values="seed")
    assert (seeds.nunique(axis=1) == 1).all()


def test_zero_workers_is_one_clear_error_and_no_output(tmp_path, capsys):
    code = main(["sweep", str(write_sweep(tmp_path)), "--out", str(tmp_path / "o"),
                 "--workers", "0"])
    assert code == 2 and "--workers 0" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_a_section_in_the_grid_merges_and_keeps_each_policy(tmp_path):
    """A whole section given as a grid value merges into it: the sweep's policy stays."""
    path = write_sweep(tmp_path, grid={"controller": [{"nominal_cycle_s": 22.5872}]},
                       policies=["non-adaptive", "adaptive"])
    sweep = load_sweep(path)
    assert [p.scenario.controller.policy for p in sweep.points] == ["non-adaptive", "adaptive"]
    bad = write_sweep(tmp_path, grid={"controller": [{"policy": "adaptive"}]})
    with pytest.raises(ScenarioError, match="cannot be varied"):
        load_sweep(bad)


def test_a_grid_over_a_distribution_parameter(tmp_path):
    path = write_sweep(tmp_path, grid={"arrivals.params.loc": [16.0, 17.6019]},
                       policies=["adaptive"])
    sweep = load_sweep(path)
    assert [p.scenario.arrivals.params["loc"] for p in sweep.points] == [16.0, 17.6019]
    assert all(p.scenario.arrivals.params["scale"] == 5.4342 for p in sweep.points)
