"""The sensor-quality map (cell.reporting.maps.sensor_map): its reading from the numbers, the
committed reports/sensor against its own CSV, and the README's quote of its headline."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cell.experiments.sweep import load_sweep
from cell.reporting.maps.sensor_map import headline, reading, table, write
from cell.scenario import catalog
from tests.prose import in_order

ROOT = catalog.BUILT_IN.parent.parent
COMMITTED = ROOT / "reports" / "sensor"


def synthetic(n: int = 8) -> pd.DataFrame:
    """Replications: the fixed robot delivers 300; the adaptive 400 with the ideal look-ahead,
    380 with the reference sensor, 370 at 1 in of error, 320 at 4 in (under 90 % of the
    reference's advantage of 80), and as many as the fixed robot at a 30 in range."""
    rng = np.random.default_rng(1)
    base = 300.0 + rng.normal(0, 3.0, n)
    rows = []
    settings = [("non-adaptive", None, {}, 0.0), ("adaptive", "ideal", {}, 100.0),
                ("adaptive", "reference", {}, 80.0),
                ("adaptive", "noise_1", {"sensor.noise_sd_in": 1.0}, 75.0),
                ("adaptive", "noise_4", {"sensor.noise_sd_in": 4.0}, 20.0),
                ("adaptive", "range_30", {"sensor.position_in": 30.0}, 0.0)]
    for policy, name, given, gain in settings:
        for r in range(n):
            d = base[r] + gain + (rng.normal(0, 0.01) if policy == "adaptive" else 0.0)
            rows.append({"arrivals.name": "thesis", "policy": policy, "sensor.name": name,
                         "replication": r, "parts_delivered": d, "parts_missed": 500 - d,
                         "spacing_outside_tol": 0.0 if policy == "adaptive" else d,
                         "parts_per_hr_wallclock": d / 3.0, "parts_bound": 500.0,
                         "sensor.noise_sd_in": np.nan, "sensor.position_in": np.nan, **given})
    return pd.DataFrame(rows)


def test_the_reading_says_how_good_the_sensor_must_be():
    t = table(synthetic(), 135.5)
    text = " ".join(reading(t))
    # advantages over the fixed robot: 100 ideal, 80 reference; 75 at sd 1 in keeps 90 % of
    # the reference's, 20 at sd 4 in does not; none at a 30 in range
    assert in_order(text, "ideal look-ahead overstates", f"by {100 / 80 - 1:.0%}")
    assert in_order(text, "error of sd 1 in", "(not", "sd 4 in)")
    assert in_order(text, "range of 135.5 in", "(not", "range of 30 in)")
    assert in_order(text, "advantage is gone", "95 % interval", "range of 30 in")
    assert in_order(headline(t), "100.0 against 80.0 parts per 500", "thesis arrivals")


def test_the_sweep_file_varies_one_quality_at_a_time():
    s = load_sweep("sensor")
    adaptive = [p.scenario.sensor for p in s.points if p.policy == "adaptive"]
    assert {m.lookahead for m in adaptive} == {"ideal", "sensor"}
    for m in adaptive:
        worse = [m.position_in is not None, m.noise_sd_in > 0, m.latency_s > 0,
                 m.miss_probability > 0]
        assert sum(worse) <= 1
    assert {p.scenario.arrivals.distribution for p in s.points} == {"weibull_min", "gamma"}


def test_the_committed_map_reads_what_its_csv_says():
    t = pd.read_csv(COMMITTED / "sensor.csv")
    text = (COMMITTED / "README.md").read_text(encoding="utf-8")
    for sentence in reading(t) + [headline(t)]:
        assert sentence in text
    assert (COMMITTED / "sensor.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_readme_quotes_the_headline():
    t = pd.read_csv(COMMITTED / "sensor.csv")
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert headline(t) in readme


@pytest.mark.usefixtures("unlaid")  # the map drawn, rendered in the byte-for-byte test below
def test_written_as_a_set(tmp_path):
    path = tmp_path / "reps.csv"
    synthetic().to_csv(path, index=False)
    out = write(path, tmp_path / "sensor")
    assert sorted(p.name for p in out.iterdir()) == ["README.md", "sensor.csv", "sensor.png"]


# --------------------------------------------------------------------------- money
@pytest.fixture(scope="module")
def costed() -> pd.DataFrame:
    """:func:`synthetic` with what the money reading reads, each row pointing at the committed
    sweep's point of its policy and sensor: a run of 3 h, no downtime."""
    sweep = load_sweep("sensor")
    point = {(p.policy, dict(p.names).get("sensor")): p.index for p in sweep.points
             if dict(p.names)["arrivals"] == "thesis"}
    reps = synthetic()
    return reps.assign(point=[point[(p, s if isinstance(s, str) else None)]
                              for p, s in zip(reps["policy"], reps["sensor.name"])],
                       parts_scrapped=0, sim_end_s=3 * 3600.0, robot_down_fraction=0.0,
                       robot_failures=0)


@pytest.mark.usefixtures("unlaid")  # reads the CSV and the text, not the map
def test_the_money_reading_is_each_options_cost_by_hand(tmp_path, costed):
    """With the sweep file, each option's cost per run is its lost parts at 12 and its hours at
    the options it has (robot 6, adaptive controller 0.5, sensor 0.4 an hour); the reading
    names the cheapest option that meets each loss target, the ideal look-ahead left out."""
    from cell.reporting.maps.sensor_map import LOSS_TARGETS

    path = tmp_path / "reps.csv"
    reps = costed
    reps.to_csv(path, index=False)
    write(path, tmp_path / "sensor", ROOT / "scenarios" / "sensor.yaml")
    t = pd.read_csv(tmp_path / "sensor" / "sensor.csv")
    hourly = {"fixed cycle": 6.0, "ideal": 6.5}
    for _, row in t.iterrows():
        runs = reps[(reps["sensor.name"].fillna("fixed cycle") == row["sensor"])]
        lost = (500 - runs["parts_delivered"]).mean()
        assert row["lost"] == pytest.approx(lost) and row["hours"] == pytest.approx(3.0)
        assert row["options_per_h"] == hourly.get(row["sensor"], 6.9)
        assert row["cost"] == pytest.approx(12 * lost + 3.0 * row["options_per_h"])
        assert row["cost_per_good_part"] == pytest.approx(row["cost"] / runs["parts_delivered"].mean())
    text = (tmp_path / "sensor" / "README.md").read_text(encoding="utf-8")
    buyable = t[t["sensor"] != "ideal"]
    for target in LOSS_TARGETS:
        meets = buyable[buyable["lost"] <= target]
        if len(meets):
            best = meets.loc[meets["cost_per_good_part"].idxmin()]
            assert f"cheapest with {best['sensor']}, {best['cost_per_good_part']:.4f}" in text


def test_without_costs_the_map_is_as_before(tmp_path, costed):
    """No sweep file, or one whose scenarios have no costs: the same three files, byte for byte."""
    path = tmp_path / "reps.csv"
    costed.to_csv(path, index=False)
    plain = tmp_path / "plain.yaml"
    plain.write_text("\n".join(line for line in (ROOT / "scenarios" / "sensor.yaml").read_text(
        encoding="utf-8").splitlines() if not line.strip().startswith("costs.")) + "\n")
    (tmp_path / "baseline.yaml").write_text((ROOT / "scenarios" / "baseline.yaml").read_text())
    a, b = write(path, tmp_path / "a"), write(path, tmp_path / "b", plain)
    for name in ("README.md", "sensor.csv", "sensor.png"):
        assert (a / name).read_bytes() == (b / name).read_bytes()
    assert "lost" not in pd.read_csv(a / "sensor.csv").columns


def test_the_committed_money_follows_from_its_own_csv():
    """reports/sensor/sensor.csv's cost is its own counts at scenarios/sensor.yaml's prices."""
    import yaml

    prices = yaml.safe_load((ROOT / "scenarios" / "sensor.yaml").read_text())["set"]
    t = pd.read_csv(COMMITTED / "sensor.csv")
    hand = (t["lost"] * prices["costs.part_value"] + t["down_h"] * prices["costs.downtime_per_h"]
            + t["repairs"] * prices["costs.repair"] + t["maintenance"] * prices["costs.maintenance"]
            + t["options_per_h"] * t["hours"])
    assert (hand / t["cost"] - 1).abs().max() < 1e-9
    assert ((t["cost"] / t["good"]) / t["cost_per_good_part"] - 1).abs().max() < 1e-9
    # the options each has: the robot; the adaptive controller; a physical sensor
    o = {k.split(".")[-1]: v for k, v in prices.items() if k.startswith("costs.options_per_h")}
    want = o["robot"] + (t["policy"] == "adaptive") * o["adaptive_controller"] \
        + ((t["policy"] == "adaptive") & (t["sensor"] != "ideal")) * o["sensor"]
    assert (t["options_per_h"] - want).abs().max() < 1e-12
    # lost and good: parts_lost (no scrap without failures) and what was delivered
    assert (t["lost"] - t["parts_lost"]).abs().max() < 1e-9
    assert (t["good"] - t["parts_delivered"]).abs().max() < 1e-9
    text = (COMMITTED / "README.md").read_text(encoding="utf-8")
    for arrivals in t["arrivals"].unique():
        buyable = t[(t["arrivals"] == arrivals) & (t["sensor"] != "ideal")]
        best = buyable.loc[buyable["cost_per_good_part"].idxmin()]
        assert f"cheapest with {best['sensor']}, {best['cost_per_good_part']:.4f} a good part" in text
