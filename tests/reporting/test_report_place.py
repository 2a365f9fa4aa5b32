"""Where a sweep's report goes: a folder of its own, a shared one, the results folder;
Table 7.1's files with the rest, and only for the thesis's own cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli.main import main
from cell.experiments.sweep import load_sweep
from cell.scenario import catalog

# Figures built, not laid out: these tests read which files are written where.
pytestmark = pytest.mark.usefixtures("unlaid")

ROOT = Path(__file__).resolve().parents[2]
WHATIF = ROOT / "reports" / "whatif"


# --------------------------------------------------------------------------- where the report goes
@pytest.fixture
def stand_in(sweeps, monkeypatch):
    """The stand-in replication (tests/conftest.py) in place of the cell's runs: where a report
    goes does not hang on its numbers."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)


def test_a_shared_report_folder_gets_a_subfolder_and_keeps_its_files(sweeps, tmp_path, stand_in):
    shared = tmp_path / "reports"
    shared.mkdir()
    (shared / "README.md").write_text("mine\n")
    path = sweeps.write(tmp_path, replications=2, batch=2,  # laid out like Table 7.1
                        set={"run.parts": 500})
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(shared)])
    assert code == 0
    assert sorted(p.name for p in shared.iterdir()) == ["README.md", "sweep"]
    assert (shared / "README.md").read_text() == "mine\n"
    assert {"report.md", "table_7_1.md", "table_7_1.csv"} <= {
        p.name for p in (shared / "sweep").iterdir()}


def test_a_report_into_the_results_folder_keeps_table_7_1_with_the_report(sweeps, tmp_path,
                                                                          stand_in):
    path = sweeps.write(tmp_path, replications=2, batch=2, set={"run.parts": 500})
    out = tmp_path / "o"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1"]) == 0
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--resume",
                 "--report", str(out)]) == 0
    assert not (out / "table_7_1.md").exists() and not (out / "table_7_1.csv").exists()
    assert {"report.md", "table_7_1.md", "table_7_1.csv"} <= {
        p.name for p in (out / "sweep").iterdir()}


def test_a_report_folder_of_its_own_holds_table_7_1_beside_the_rest(sweeps, tmp_path, stand_in):
    path = sweeps.write(tmp_path, replications=2, batch=2, set={"run.parts": 500})
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")]) == 0
    names = {p.name for p in (tmp_path / "rep").iterdir()}
    assert {"table_7_1.md", "table_7_1.csv", "report.md", "summary.csv",
            "differences.csv"} <= names
    text = (tmp_path / "rep" / "report.md").read_text()
    link = "[`table_7_1.md`](table_7_1.md); its numbers: [`table_7_1.csv`](table_7_1.csv)."
    assert link in text and text.index(link) < text.index("\n## ")


@pytest.mark.parametrize("other", [
    {"run.parts": 20},                                        # the thesis's runs are 500 parts
    {"run.parts": 500, "arrivals": {"distribution": "gamma", "mean_s": 22.5872, "cv": 0.3}},
    {"run.parts": 500, "belts.output_nominal_in_s": 2.5},
])
def test_table_7_1_only_beside_the_thesis_s_own_cell(sweeps, tmp_path, other):
    """Laid out like Table 7.1 but on another cell: the general report, no thesis beside it."""
    from cell.reporting.table_7_1.table import is_table_7_1

    sweep = load_sweep(sweeps.write(tmp_path, replications=2, batch=2, set=other))
    assert not is_table_7_1(sweep)
    same = load_sweep(sweeps.write(tmp_path, replications=2, batch=2,
                                   set={"run.parts": 500, "robot.timing": "minimum-time"}))
    assert is_table_7_1(same)  # the thesis's cell under another robot timing (make sweep-mintime)


def test_table_7_1_reads_the_thesis_s_cell_once_for_all_points(sweeps, tmp_path, monkeypatch):
    """Three points, each checked against the built-in baseline: read once, not per point."""
    from cell.reporting.table_7_1.table import is_table_7_1
    from cell.scenario import yamlio

    sweep = load_sweep(sweeps.write(tmp_path, replications=2, batch=2, set={"run.parts": 500}))
    read, reads = yamlio.load_mapping, []

    def counting(path, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        reads.append(Path(path) == catalog.path("baseline"))
        return read(path, *args, **kwargs)

    monkeypatch.setattr(yamlio, "load_mapping", counting)
    assert len(sweep.points) == 3 and is_table_7_1(sweep)
    assert reads == [True]


@pytest.mark.parametrize("make", ["file", "parent-file"])
def test_bad_report_target_one_line_exit_2_nothing_written(sweeps, tmp_path, capsys, make):
    blocker = tmp_path / "blocker"
    blocker.write_text("x")
    report = blocker if make == "file" else blocker / "rep"
    code = main(["sweep", str(sweeps.write(tmp_path)), "--out", str(tmp_path / "o"),
                 "--workers", "1", "--report", str(report)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "blocker" in err
    assert not (tmp_path / "o").exists()
