"""The disk cache (cell.plumbing.cache): exact values, silent recomputation, never another result."""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys

import pytest

from cell.plumbing import cache
from cell.scenario.schema import load_scenario
from cell.sim import timing_cache
from cell.sim.simulation import simulate


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    """Each test with a cache directory of its own and nothing remembered in this process."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv(cache.NO_CACHE_ENV, raising=False)
    _forget()
    yield tmp_path / "xdg" / "cell"
    _forget()


def _forget() -> None:
    cache.forget()  # the point is to read from disk


VALUE = {"x": [0.1, 1 / 3, -0.0, 5e-324, 1.7976931348623157e308, math.inf], "n": 3, "s": "ok"}


def test_values_come_back_exactly(own_cache):
    cache.store("demo", {"a": 1.5}, VALUE)
    got = cache.stored("demo", {"a": 1.5})
    assert got == VALUE
    assert [math.copysign(1, v) for v in got["x"]] == [math.copysign(1, v) for v in VALUE["x"]]
    assert cache.stored("demo", {"a": 1.5000000000000002}) is None     # another key
    assert [p.name.startswith("demo-") for p in own_cache.iterdir()] == [True]


def test_a_nan_survives_too():
    cache.store("demo", [1], {"v": math.nan})
    assert math.isnan(cache.stored("demo", [1])["v"])


@pytest.mark.parametrize("damage", ["flip a byte", "truncate", "garbage", "empty"])
def test_a_damaged_entry_is_a_miss(own_cache, damage):
    cache.store("demo", [2], VALUE)
    (path,) = own_cache.iterdir()
    data = bytearray(path.read_bytes())
    if damage == "flip a byte":
        data[-5] ^= 0x01
    elif damage == "truncate":
        data = data[: len(data) // 2]
    elif damage == "garbage":
        data = bytearray(b"\x00\xff" * 40)
    else:
        data = bytearray()
    path.write_bytes(bytes(data))
    assert cache.stored("demo", [2]) is None


def test_another_version_of_the_code_does_not_read_the_entry(monkeypatch):
    cache.store("demo", [3], VALUE)
    monkeypatch.setattr(cache, "code_fingerprint", lambda: "another version")
    assert cache.stored("demo", [3]) is None


def test_turned_off_it_neither_reads_nor_writes(own_cache, monkeypatch):
    cache.store("demo", [4], VALUE)
    monkeypatch.setenv(cache.NO_CACHE_ENV, "1")
    assert cache.stored("demo", [4]) is None
    cache.store("demo", [5], VALUE)
    monkeypatch.delenv(cache.NO_CACHE_ENV)
    assert cache.stored("demo", [5]) is None and cache.stored("demo", [4]) == VALUE


def test_an_unwritable_cache_is_silent(tmp_path, monkeypatch):
    (tmp_path / "file").write_text("not a directory")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "file"))
    cache.store("demo", [6], VALUE)           # no error
    assert cache.stored("demo", [6]) is None


def _segments(t):
    return {name: [getattr(t, name).time(v) for v in (0.5, 1.0, 2.0, 3.0, 7.5, 40.0)]
            for name in ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")}


def test_a_remembered_value_outlives_the_process_but_not_a_failed_read_back(own_cache):
    kept = cache.Remembered("square", to_plain=lambda v: {"v": v}, from_plain=lambda p: p["v"])
    assert kept.get({"x": 3}) is None
    kept.put({"x": 3}, 9.0)
    assert kept.get({"x": 3}) == 9.0
    cache.forget()                      # a new process: only the disk remembers
    assert kept.get({"x": 3}) == 9.0
    other = cache.Remembered("square", from_plain=lambda p: p["missing"])
    assert other.get({"x": 3}) is None  # stored, but not readable as this kind: a miss
    kept.put({"x": object()}, 1.0)      # a key that is not plain data is not kept
    assert kept.get({"x": object()}) is None
    kept.put({"y": 1}, {"not": {1, 2}})  # a value the disk cannot take stays in this process
    assert kept.get({"y": 1}) == {"not": {1, 2}}
    cache.forget()
    assert kept.get({"y": 1}) is None


def test_a_remembered_key_is_made_text_once_per_look_and_once_per_keep(own_cache, monkeypatch):
    """A miss looks here and on disk with the one text of the key; keeping it writes both with
    one text too; the entry is the one :func:`cache.stored` finds under the key."""
    kept = cache.Remembered("count")
    key = {"x": [1.5, 2]}
    dumps, made = cache.json.dumps, []

    def counting(obj, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        made.append(obj is key)
        return dumps(obj, *args, **kwargs)

    monkeypatch.setattr(cache.json, "dumps", counting)
    assert kept.get(key) is None and made.count(True) == 1
    kept.put(key, 4.0)
    assert made.count(True) == 2
    monkeypatch.setattr(cache.json, "dumps", dumps)
    assert cache.stored("count", {"x": [1.5, 2]}) == 4.0


@pytest.mark.parametrize("timing", ["constant-rate", "minimum-time"])
def test_the_timing_read_back_is_the_solved_one(own_cache, timing):
    s = load_scenario("baseline", {"robot.timing": timing, "mintime.grid_points": 120})
    solved = timing_cache.robot_timing(s)
    assert any(p.name.startswith("timing-") for p in own_cache.iterdir())
    _forget()
    read = timing_cache.robot_timing(s)
    assert read is not solved
    assert _segments(read) == _segments(solved)
    assert {n: getattr(read, n) for n in ("r2_min_s", "r4_min_s", "r4_nominal_s",
                                          "input_track_max_in_s")} == \
        {n: getattr(solved, n) for n in ("r2_min_s", "r4_min_s", "r4_nominal_s",
                                         "input_track_max_in_s")}
    assert read.r2.velocity(30.0) == solved.r2.velocity(30.0)


def test_a_run_is_the_same_with_the_cache_off_cold_and_warm(own_cache, monkeypatch):
    s = load_scenario("baseline", {"run.parts": 300, "arrivals.distribution": "gamma",
                                   "arrivals.mean_s": 21.0, "arrivals.cv": 0.4})
    monkeypatch.setenv(cache.NO_CACHE_ENV, "1")
    off = simulate(s, seed=5)
    monkeypatch.delenv(cache.NO_CACHE_ENV)
    _forget()
    cold = simulate(s, seed=5)
    _forget()
    warm = simulate(s, seed=5)
    assert _text(off) == _text(cold) == _text(warm)


def _text(result) -> list[str]:
    """Every value of a run's records and summary as exact text (NaN included)."""
    rows = [repr(tuple(r)) for r in result.records]
    return rows + [repr(dataclasses.astuple(result.summary))]


def test_a_damaged_timing_entry_is_solved_again(own_cache):
    s = load_scenario("baseline")
    solved = timing_cache.robot_timing(s)
    for path in own_cache.glob("timing-*"):
        path.write_bytes(path.read_bytes().replace(b"_ub", b"_xx"))
    _forget()
    assert _segments(timing_cache.robot_timing(s)) == _segments(solved)


def test_a_warm_start_imports_nothing_heavy(tmp_path, own_cache):
    """`cell run baseline` loads neither scipy, pandas, matplotlib nor dask once its cell
    was solved (the first run, here in-process, solves and stores it)."""
    from cell.cli.main import main

    assert not own_cache.exists()
    assert main(["run", "baseline", "--out", str(tmp_path / "out")]) == 0
    assert sorted(p.name.split("-")[0] for p in own_cache.iterdir())  # solved and stored
    env = {**os.environ, "XDG_CACHE_HOME": str(own_cache.parent)}
    code = ("import sys\nfrom cell.cli.main import main\n"
            "main(['run', 'baseline', '--out', sys.argv[1]])\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'scipy', 'pandas', 'matplotlib', 'dask', 'distributed'}))\n")
    second = subprocess.run([sys.executable, "-c", code, str(tmp_path / "again")], env=env,
                            capture_output=True, text=True, check=True).stdout
    assert second.splitlines()[-1] == "[]"
    assert (tmp_path / "out" / "parts.csv").read_bytes() == \
        (tmp_path / "again" / "parts.csv").read_bytes()


def test_an_identity_key_keeps_a_value_for_the_same_object_only():
    """memo(key=Identity): the same object is one entry; an equal but distinct object is
    another (no value carries across objects); forget() clears it like any memo."""
    from cell.plumbing import cache

    made = []

    @cache.memo(key=cache.Identity, maxsize=1)
    def build(obj):
        made.append(obj)
        return len(made)

    a, b = [1, 2], [1, 2]  # equal, not hashable, distinct
    assert build(a) == build(a) == 1
    assert build(b) == 2 and made[1] is b
    cache.forget()
    assert build(b) == 3


def test_a_memo_shared_by_threads_never_loses_an_entry_under_a_caller():
    """A dask worker's threads call the same memo side by side: one thread's eviction must
    not pull an entry out from under another (without the lock this raises KeyError)."""
    import threading

    before = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # switch threads as often as possible
    try:
        @cache.memo(maxsize=1)
        def same(x):
            return x

        errors = []

        def hammer(k):
            try:
                for _ in range(20_000):
                    assert same(k) == k
            except Exception as exc:  # noqa: BLE001 (collected and reported below)
                errors.append(repr(exc))

        threads = [threading.Thread(target=hammer, args=(i % 3,)) for i in range(6)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    finally:
        sys.setswitchinterval(before)
    assert errors == []
