"""Where a sweep's results and report go: a user's files are never replaced, and a
report that could not be written is refused before any replication runs."""

from __future__ import annotations

import pytest

from cell.cli.main import main
from tests.prose import in_order

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def test_a_folder_with_a_users_replications_csv_is_refused_and_left_alone(sweeps, tmp_path,
                                                                          capsys):
    """No sweep.json: the replications.csv is not a sweep's, so the sweep must not replace it."""
    mine = tmp_path / "data"
    mine.mkdir()
    (mine / "replications.csv").write_text("my,own,numbers\n")
    code = main(["sweep", str(sweeps.write(tmp_path)), "--out", str(mine), "--workers", "1"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "replications.csv" in err and "sweep.json" in err
    assert (mine / "replications.csv").read_text() == "my,own,numbers\n"
    assert sorted(p.name for p in mine.iterdir()) == ["replications.csv"]


def test_a_finished_run_of_the_same_sweep_wants_resume(sweeps, tmp_path, monkeypatch, capsys):
    """Run twice without --resume: the second is refused, nothing lost; with it, nothing runs."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.first_draw)
    args = ["sweep", str(sweeps.write(tmp_path)), "--out", str(tmp_path / "o"), "--workers", "1"]
    assert main(args) == 0, capsys.readouterr().err
    before = {p: p.read_bytes() for p in (tmp_path / "o").rglob("*") if p.is_file()}
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"cell: error: --out {tmp_path / 'o'}: ")
    assert in_order(err[0], "finished run", "(9 tasks)", "--resume")
    assert {p: p.read_bytes() for p in (tmp_path / "o").rglob("*") if p.is_file()} == before
    assert main([*args, "--resume"]) == 0
    assert "(0 tasks run, 9 reused)" in capsys.readouterr().out


@pytest.mark.parametrize("report", ["o", "o/..", "."])
def test_a_report_folder_that_holds_the_sweeps_results_is_planned_before_running(
        sweeps, tmp_path, monkeypatch, capsys, report):
    """--report DIR holding --out (the same folder, or its parent): the sweep's own files
    will be there, so the report goes to DIR/NAME/ -- decided before anything runs."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    work = tmp_path / "w"
    work.mkdir()
    monkeypatch.chdir(work)
    path = sweeps.write(tmp_path, policies=["adaptive"], grid={"run.warmup_parts": [0, 1]})
    code = main(["sweep", str(path), "--out", "o", "--workers", "1", "--report", report])
    assert code == 0, capsys.readouterr().err
    folder = (work / report).resolve() / "sweep"
    assert (folder / "report.md").is_file() and (work / "o" / "replications.csv").is_file()


@pytest.mark.parametrize("reaches", ["real", "real/o"])
def test_a_report_folder_reached_through_a_symlink_is_planned_like_the_plain_one(
        sweeps, tmp_path, monkeypatch, capsys, reaches):
    """--report LINK where LINK leads to --out or to its parent: the same folder as the plain
    case, so the report goes to LINK/NAME/, decided before the run, not refused after it."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    (tmp_path / "real").mkdir()  # empty: the sweep makes --out (a LINK to it dangles till then)
    link = tmp_path / "link"
    link.symlink_to(tmp_path / reaches, target_is_directory=True)
    path = sweeps.write(tmp_path, policies=["adaptive"], grid={"run.warmup_parts": [0, 1]})
    code = main(["sweep", str(path), "--out", str(tmp_path / "real" / "o"), "--workers", "1",
                 "--report", str(link)])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / reaches / "sweep" / "report.md").is_file()
    assert (tmp_path / "real" / "o" / "replications.csv").is_file()


def test_a_report_subfolder_reached_through_a_symlink_that_is_the_results_is_refused(
        sweeps, tmp_path, monkeypatch, capsys):
    """--report LINK, LINK leading to --out's parent and --out being LINK/NAME: refused in one
    line before anything runs, as without the link."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.Interrupt(0))
    (tmp_path / "real").mkdir()
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "real", target_is_directory=True)
    path = sweeps.write(tmp_path, policies=["adaptive"], grid={"run.warmup_parts": [0, 1]})
    out = tmp_path / "real" / "sweep"
    code = main(["sweep", str(path), "--out", str(out), "--workers", "1", "--report", str(link)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"--report {link}:" in err and f"--out {out}" in err
    assert not (out / "replications.csv").exists()


def test_a_shared_report_folder_keeps_the_letters_of_a_non_english_name(sweeps, tmp_path,
                                                                       monkeypatch, capsys):
    """The subfolder is the sweep's name with only separators replaced: 'Étude / ligne 3'
    goes to Étude_ligne_3, not to 'tude_ligne_3'."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    shared = tmp_path / "reports"
    shared.mkdir()
    (shared / "notes.txt").write_text("mine\n")
    path = sweeps.write(tmp_path, name="Étude / ligne 3", policies=["adaptive"],
                        grid={"run.warmup_parts": [0, 1]})
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(shared)])
    assert code == 0, capsys.readouterr().err
    assert sorted(p.name for p in shared.iterdir()) == ["notes.txt", "Étude_ligne_3"]


@pytest.mark.parametrize(("report", "out"), [(".", "sweep"), ("rep", "rep/sweep/data")])
def test_a_report_subfolder_that_would_hold_the_results_is_refused_before_running(
        sweeps, tmp_path, monkeypatch, capsys, report, out):
    """--report DIR holding --out sends the report to DIR/NAME/; when that is --out itself
    (or holds it), the report could not be written there after the sweep: one line, exit 2,
    nothing run."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    work = tmp_path / "w"
    work.mkdir()
    monkeypatch.chdir(work)
    path = sweeps.write(tmp_path, policies=["adaptive"], grid={"run.warmup_parts": [0, 1]})
    code = main(["sweep", str(path), "--out", out, "--workers", "1", "--report", report])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"--report {report}:" in err and f"--out {out}" in err
    assert not (work / out / "replications.csv").exists()


def test_a_folder_of_results_without_sweep_json_is_refused_naming_them(tmp_path):
    """The refusal names what a sweep would replace: replications.csv, then the first task file."""
    from cell.experiments.sweep.outdir import check_out
    from cell.plumbing.errors import CellError

    out = tmp_path / "o"
    (out / "tasks").mkdir(parents=True)
    check_out(out)  # an empty tasks/ holds nothing of a sweep's
    for name in ("task-000002.csv", "task-000001.csv"):
        (out / "tasks" / name).write_text("x\n")
    with pytest.raises(CellError) as tasks_only:
        check_out(out)
    (out / "replications.csv").write_text("x\n")
    with pytest.raises(CellError) as both:
        check_out(out)
    for error, names in ((tasks_only, "tasks/task-000001.csv"),
                         (both, "replications.csv, tasks/task-000001.csv")):
        message = str(error.value)  # the folder, what it holds, what it lacks, the way out
        assert message.startswith(f"--out {out}: holds {names} ")
        assert in_order(message, "no sweep.json", "another --out")
