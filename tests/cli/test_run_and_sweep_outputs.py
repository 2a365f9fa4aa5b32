"""What cell run and cell sweep write and refuse: a run's folder is not replaced unless
--force, belts.csv holds real changes only, Parquet holds what the CSV does (a run's three
files, a sweep's result file), cell sweep takes --set, usage errors point to the
subcommand's help once, and a refusal names the key to change."""

from __future__ import annotations

import duckdb
import pandas as pd

from cell.cli.main import main

RUN = ["run", "baseline", "--set", "run.parts=20"]


def test_run_into_another_runs_folder_is_refused_and_left_as_it_was(tmp_path, capsys):
    out = tmp_path / "r"
    assert main([*RUN, "--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    assert main([*RUN, "--set", "run.seed=5", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "another run's files" in err and "--force" in err and err.count("\n") == 1
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert main([*RUN, "--set", "run.seed=5", "--out", str(out), "--force"]) == 0
    assert (out / "parts.csv").read_bytes() != before["parts.csv"]


def test_belts_csv_has_one_row_per_real_change(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "baseline", "--set", "run.parts=200", "--out", str(out)]) == 0
    belts = pd.read_csv(out / "belts.csv")
    for _, b in belts.groupby("belt"):
        v = b["speed_in_s"].to_numpy()
        assert len(v) > 10 and (v[1:] != v[:-1]).all()  # no row repeats the speed before it


def test_parquet_holds_the_csvs_columns_types_and_values(tmp_path):
    csv, pq = tmp_path / "c", tmp_path / "p"
    assert main([*RUN, "--out", str(csv)]) == 0
    assert main([*RUN, "--out", str(pq), "--format", "parquet"]) == 0
    assert sorted(p.name for p in pq.iterdir()) == ["belts.parquet", "parts.parquet",
                                                    "summary.parquet"]
    for name in ("parts", "summary", "belts"):
        a = pd.read_csv(csv / f"{name}.csv")
        b = pd.read_parquet(pq / f"{name}.parquet")
        pd.testing.assert_frame_equal(a, b)
        d = duckdb.sql(f"select * from read_parquet('{pq / f'{name}.parquet'}')").df()
        assert list(d.columns) == list(a.columns) and len(d) == len(a)
        for c in a.columns:  # the same values whichever engine reads them
            if pd.api.types.is_numeric_dtype(a[c]):
                pd.testing.assert_series_equal(a[c], d[c].astype(a[c].dtype), check_names=False)


def test_sweep_takes_set_and_writes_its_result_file_as_parquet_instead(sweeps, tmp_path):
    """``--format parquet``: replications.parquet is the result file, replications.csv is
    not written; it holds what the CSV of the same sweep holds (columns, types, values, as
    pandas and DuckDB read it), and --resume reads the tasks back into it again."""
    path = sweeps.write(tmp_path, set={"run.parts": 10}, grid={"belts.output_nominal_in_s": [1.8, 2.0]},
                        policies=["adaptive"], replications=2, batch=1)
    csv, pq = tmp_path / "c", tmp_path / "p"
    for out, fmt in ((csv, "csv"), (pq, "parquet")):
        assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--set",
                     "run.parts=12", "--format", fmt]) == 0
    assert not (pq / "replications.csv").exists() and not (csv / "replications.parquet").exists()
    frame = pd.read_csv(csv / "replications.csv")
    assert (frame["parts_arrived"] == 12).all() and len(frame) == 4  # --set over the file's set
    pd.testing.assert_frame_equal(frame, pd.read_parquet(pq / "replications.parquet"))
    d = duckdb.sql(f"select * from read_parquet('{pq / 'replications.parquet'}')").df()
    assert list(d.columns) == list(frame.columns) and len(d) == len(frame)
    # a resumed sweep, a task lost: the result file is assembled again, still Parquet only
    (pq / "replications.parquet").unlink()
    next((pq / "tasks").iterdir()).unlink()
    assert main(["sweep", str(path), "--out", str(pq), "--workers", "1", "--set",
                 "run.parts=12", "--format", "parquet", "--resume"]) == 0
    pd.testing.assert_frame_equal(frame, pd.read_parquet(pq / "replications.parquet"))
    # and the same folder resumed as CSV: the Parquet file goes, one result file is left
    assert main(["sweep", str(path), "--out", str(pq), "--workers", "1", "--set",
                 "run.parts=12", "--resume"]) == 0
    assert (pq / "replications.csv").read_bytes() == (csv / "replications.csv").read_bytes()
    assert not (pq / "replications.parquet").exists()


def test_a_usage_error_points_to_the_subcommands_help_once(capsys):
    assert main(["sweep", "x", "--out", "y", "--frobnicate"]) == 2
    err = capsys.readouterr().err.strip()
    # every refusal opens "cell: error: "; the subcommand is named once, with its own --help
    assert "\n" not in err and err.startswith("cell: error: sweep: ") and "--frobnicate" in err
    assert err.endswith("(see cell sweep --help)") and err.count("sweep") == 2


def test_a_heavy_part_refused_names_the_belt_speed_key(tmp_path, capsys):
    assert main([*RUN, "--set", "part.weight_oz=12", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "part.weight_oz" in err and "belts.output_nominal_in_s" in err
    assert not (tmp_path / "r").exists()
