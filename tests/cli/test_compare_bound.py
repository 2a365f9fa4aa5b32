"""cell compare says both sides' parts delivered as a share of their bound (issue 22, item
4): the means are each side's runs' parts_delivered / parts_bound, the difference paired
replication by replication, the line said but not counted in the overall verdict; report.md
has the share beside each policy's deliveries."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import main
from cell.experiments.stats import paired_difference

# Figures built, not laid out: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def test_compare_gives_each_sides_share_of_the_bound(tmp_path, capsys):
    fast = tmp_path / "fast.yaml"  # parts faster than the robot's fastest cycle: bound < arrived
    fast.write_text("name: fast\narrivals: {distribution: gamma, mean_s: 12.0, cv: 0.3}\n"
                    "controller: {nominal_cycle_s: null}\n")
    out_dir = tmp_path / "out"
    assert main(["compare", str(fast), "baseline", "--set", "run.parts=24", "--replications",
                 "3", "--workers", "1", "--out", str(out_dir)]) == 0
    out = capsys.readouterr().out.split("\nwrote ")[0]
    line = next(x for x in out.splitlines() if x.strip().startswith("Delivered of the bound"))
    runs = pd.read_csv(out_dir / "replications.csv")
    share = {label: (100.0 * g.sort_values("replication")["parts_delivered"]
                     / g.sort_values("replication")["parts_bound"]).to_numpy(float)
             for label, g in runs.groupby("scenario")}
    assert (runs["parts_bound"] < runs["parts_arrived"]).any()  # not the service level
    assert all((s <= 100.0).all() for s in share.values())
    ma, mb = (float(x) for x in re.search(r"means (\S+) against (\S+)$", line).groups())
    assert np.isclose(ma, share["fast"].mean(), rtol=1e-5)
    assert np.isclose(mb, share["baseline"].mean(), rtol=1e-5) and mb == 100.0
    d = paired_difference(share["fast"], share["baseline"])
    shown, half = (float(x) for x in re.search(r"fast - baseline (\S+) ± (\S+)", line).groups())
    assert abs(shown - float(d["mean"])) <= 0.5 and np.isclose(
        half, (float(d["ci_high"]) - float(d["ci_low"])) / 2, atol=0.5)
    # the rates differ: the overall line counts every judged line but this one
    said = [x for x in out.splitlines()[1:-1] if re.match(r"  \S.*?\S {2,}\S", x)
            and "not judged" not in x and "not compared" not in x
            and not x.strip().startswith("OEE losses")]  # shown beside OEE, never judged
    assert line in said
    assert out.splitlines()[-1].endswith(f" of {len(said) - 1})")
    text = (out_dir / "report.md").read_text()
    head = next(x for x in text.split("## Parts delivered")[1].splitlines() if x.startswith("| "))
    assert head.count("| of bound % |") == runs["policy"].nunique() == 1  # a policy, a share
    differences = pd.read_csv(out_dir / "differences.csv")
    row = differences[differences["measure"] == "delivered_of_bound_pct"].iloc[0]
    assert np.isclose(row["mean"], float(d["mean"]))
