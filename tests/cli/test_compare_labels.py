"""What ``cell compare A B`` calls A and B: their ``name:``, else their file names, else
``A: ...`` and ``B: ...``; the same in the verdict, report.md and every CSV."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml

from cell.cli.compare import labels
from cell.cli.main import main
from cell.scenario.schema import load_scenario

# Figures built, not laid out: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def write(path: Path, name: str | None, **run: object) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    doc: dict[str, object] = {"run": {"parts": 12, **run}}
    if name is not None:
        doc["name"] = name
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.mark.parametrize(("a", "b", "expected"), [
    (("x/fast.yaml", "fast line"), ("y/slow.yaml", "slow line"), ("fast line", "slow line")),
    (("x/fast.yaml", "fast line"), ("y/slow.yaml", None), ("fast line", "slow")),
    (("x/fast.yaml", "line 3"), ("y/slow.yaml", "line 3"), ("fast", "slow")),  # copied name
    (("x/fast.yaml", None), ("y/slow.yaml", None), ("fast", "slow")),
    (("x/base.yaml", None), ("y/base.yaml", None), ("A: base", "B: base")),
    (("x/base.yaml", "line 3"), ("y/base.yaml", "line 3"), ("A: line 3", "B: line 3")),
    (("x/base.yaml", "one"), ("y/base.yaml", "two"), ("one", "two")),
])
def test_the_first_of_names_file_names_and_a_b_that_tells_them_apart(tmp_path, a, b, expected):
    pa, pb = write(tmp_path / a[0], a[1]), write(tmp_path / b[0], b[1])
    assert labels(load_scenario(pa), load_scenario(pb), str(pa), str(pb)) == expected


def test_a_built_in_goes_by_its_name():
    a, b = load_scenario("baseline"), load_scenario("non_adaptive")
    assert labels(a, b, "baseline", "non_adaptive") == ("baseline", "non_adaptive")
    assert labels(a, a, "baseline", "baseline") == ("A: baseline", "B: baseline")


@pytest.mark.parametrize(("names", "expected"), [
    (("fast line", "slow line"), ("fast line", "slow line")),
    ((None, None), ("A: base", "B: base")),
])
def test_the_labels_are_the_verdicts_the_reports_and_the_csvs(tmp_path, capsys, names,
                                                              expected):
    """Two files both called base.yaml, in two folders."""
    a = write(tmp_path / "a" / "base.yaml", names[0])
    b = write(tmp_path / "b" / "base.yaml", names[1], warmup_parts=2)  # windows apart
    out = tmp_path / "cmp"
    code = main(["compare", str(a), str(b), "--replications", "2", "--workers", "1",
                 "--out", str(out)])
    said, err = capsys.readouterr()
    assert code == 0, err
    la, lb = expected
    assert said.startswith(f"{la} (adaptive) against {lb} (adaptive): ")
    assert f"{la} has run.warmup_parts 0, {lb} 2" in err
    report = (out / "report.md").read_text()
    assert report.startswith(f"# compare: {la} against {lb}\n")
    assert f"| {la} | " in report and f"| {lb} | " in report
    for name in ("summary.csv", "replications.csv"):
        assert set(pd.read_csv(out / name)["scenario"]) == {la, lb}, name
    diffs = pd.read_csv(out / "differences.csv")
    # the baseline named by its scenario's name alone, as the report names it (issue 24)
    assert set(diffs["scenario"]) == {la} and set(diffs["versus"]) == {lb}
