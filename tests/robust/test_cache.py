"""A cache that cannot lie: a garbled or truncated entry under XDG_CACHE_HOME is ignored and
rebuilt, and the run's files are byte for byte a cold run's; a cache folder that cannot be
made is skipped quietly; a relative XDG_CACHE_HOME is not used (nothing in the working
directory)."""

from __future__ import annotations

import os

import pytest

from cell.cli.main import main
from cell.plumbing import cache
from cell.scenario import catalog

RUN = ["run", str(catalog.path("baseline")), "--set", "run.parts=40"]


def _run(out, capsys):
    cache.forget()  # this process remembers nothing: the disk is read
    code = main([*RUN, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    return {p.name: p.read_bytes() for p in out.iterdir()}, err


@pytest.fixture
def cold(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv(cache.NO_CACHE_ENV, raising=False)
    files, _ = _run(tmp_path / "cold", capsys)
    entries = sorted((tmp_path / "xdg" / "cell").glob("timing-*.json"))
    assert entries  # the run stored its robot timing
    return files, entries


@pytest.mark.parametrize("damage", ["garbled", "truncated", "numbers changed"])
def test_a_damaged_entry_is_ignored_rebuilt_and_the_run_unchanged(cold, tmp_path, capsys,
                                                                  damage):
    files, (entry, *_) = cold
    data = entry.read_bytes()
    if damage == "garbled":
        bad = data[:40] + bytes(b ^ 0x5A for b in data[40:80]) + data[80:]
    elif damage == "truncated":
        bad = data[: len(data) // 3]
    else:  # valid JSON, plausible numbers, the checksum not redone: absurd timings if used
        bad = data.replace(b'"r4_min_s": ', b'"r4_min_s": -1')
        assert bad != data
    entry.write_bytes(bad)
    again, err = _run(tmp_path / "warm", capsys)
    assert again == files and "cache" not in err.lower()
    assert entry.read_bytes() == data  # rebuilt: the solved value stored again


def test_a_cache_folder_that_cannot_be_made_is_skipped_quietly(tmp_path, monkeypatch, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))  # a file: no folder can be made in it
    files, err = _run(tmp_path / "o", capsys)
    assert sorted(files) == ["belts.csv", "parts.csv", "summary.csv"]
    assert "warning" not in err and sorted(os.listdir(tmp_path)) == ["file", "o"]


def test_a_relative_cache_home_is_not_used(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", "relative")
    monkeypatch.setenv("HOME", "also-relative")
    assert cache.cache_dir() is None
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.cache_dir() == tmp_path / "home" / ".cache" / "cell"
