"""make learn's training (cell.rl.train) is reproducible: the same seeds give the same weights,
to the bit, and what it keeps delivers at least what the adaptive decision (its start) does on
the training runs.  Skipped without the optional extra [rl] (cma)."""

from __future__ import annotations

import pytest

pytest.importorskip("cma")

from cell.rl import train  # noqa: E402


def test_a_short_training_twice_gives_the_same_weights(monkeypatch: pytest.MonkeyPatch) -> None:
    for name, value in (("GENERATIONS", 2), ("POPULATION", 4), ("PARTS", 30), ("SEEDS", (7001,)),
                        ("POINTS", train.POINTS[:2]), ("WORKERS", 1)):
        monkeypatch.setattr(train, name, value)
    monkeypatch.setattr(train, "OBJECTIVE", [])
    first = train.train()
    monkeypatch.setattr(train, "OBJECTIVE", [])
    again = train.train()
    assert first["theta"] == again["theta"]
    assert first["parts_delivered"] >= first["parts_delivered_adaptive"]
    assert first["parts_delivered_adaptive"] == train.score([0.0] * len(first["theta"]))
