"""The sensor-quality map (cell.reporting.maps.sensor_map): its reading from the numbers, the
committed reports/sensor against its own CSV, and the README's quote of its headline."""

from __future__ import annotations

import numpy as np
import pandas as pd

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


def test_written_as_a_set(tmp_path):
    path = tmp_path / "reps.csv"
    synthetic().to_csv(path, index=False)
    out = write(path, tmp_path / "sensor")
    assert sorted(p.name for p in out.iterdir()) == ["README.md", "sensor.csv", "sensor.png"]
