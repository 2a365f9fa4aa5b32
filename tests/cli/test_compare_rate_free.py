"""cell compare of two scenarios fed at different rates: the verdict says the rates differ
and judges on the rate-free measures (service level, parts lost per 100 arrivals), each
with both sides' means; --policy runs one policy on both sides."""

from __future__ import annotations

from cell.cli.main import main
from tests.prose import in_order


def test_compare_at_different_rates_judges_on_service_level(tmp_path, capsys):
    fast = tmp_path / "fast.yaml"
    fast.write_text("name: fast\narrivals: {distribution: gamma, mean_s: 18.0, cv: 0.1}\n"
                    "controller: {nominal_cycle_s: null}\n")
    assert main(["compare", str(fast), "baseline", "--set", "run.parts=30", "--replications", "3",
                 "--policy", "non-adaptive", "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "arrival rates differ" in out
    assert "Parts per hour (wall clock)" in out and "not judged (arrival rates differ)" in out
    line = next(x for x in out.splitlines() if x.strip().startswith("Service level"))
    assert "means" in line and " - baseline" in line
    assert out.splitlines()[-1].startswith("Overall, on the rate-free measures")
    assert in_order(out, "fast (non-adaptive)", "baseline (non-adaptive)")  # --policy: both sides
