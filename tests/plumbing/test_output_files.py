"""Files written together or not at all (cell.plumbing.output.atomic.atomic_paths), and ``cell fit``'s YAML
and PNG as such a pair: a failure or an interruption between them leaves the old pair."""

from __future__ import annotations

import contextlib
import errno
import io
import os
import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cell.cli.main import main
from cell.plumbing.output.atomic import atomic_paths

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _replace_failing_at(monkeypatch: pytest.MonkeyPatch, k: int, error: BaseException,
                        within: Path) -> list[str]:
    """``os.replace`` raises ``error`` at its ``k``-th call (counted from 1) into ``within``; the
    calls' targets there.  Others (the disk cache's entries, written as a cold cache fills) pass."""
    real, calls = os.replace, list[str]()

    def replace(src: Any, dst: Any, **kwargs: Any) -> None:
        if not Path(os.fspath(dst)).resolve().is_relative_to(within.resolve()):
            real(src, dst, **kwargs)
            return
        calls.append(os.fspath(dst))
        if len(calls) == k:
            raise error
        real(src, dst, **kwargs)

    monkeypatch.setattr(os, "replace", replace)
    return calls


def _files(*folders: Path) -> dict[str, bytes | None]:
    """Everything under ``folders``: a file's bytes, None for a directory."""
    return {os.fspath(p): None if p.is_dir() else p.read_bytes() for d in folders for p in d.rglob("*")}


def _write(tmps: tuple[Path, ...], texts: tuple[str, ...]) -> None:
    for tmp, text in zip(tmps, texts):
        tmp.write_text(text)


def test_files_in_two_directories_appear_together(tmp_path: Path) -> None:
    a, b = tmp_path / "one" / "a.yaml", tmp_path / "two" / "b.png"
    with atomic_paths(a, b) as tmps:
        _write(tmps, ("A", "B"))
    assert _files(a.parent, b.parent) == {str(a): b"A", str(b): b"B"}


@pytest.mark.parametrize("error", [OSError(errno.EIO, "Input/output error"), KeyboardInterrupt()],
                         ids=["failed rename", "Ctrl-C"])
@pytest.mark.parametrize("old", [False, True], ids=["new files", "old files"])
def test_a_failing_second_rename_puts_the_first_back(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                     error: BaseException, old: bool) -> None:
    a, b = tmp_path / "x" / "a.yaml", tmp_path / "b.png"
    a.parent.mkdir()
    if old:
        a.write_text("old A")
        b.write_text("old B")
    before = _files(tmp_path)
    calls = _replace_failing_at(monkeypatch, 2, error, tmp_path)
    with pytest.raises(Exception if isinstance(error, OSError) else KeyboardInterrupt):
        with atomic_paths(a, b) as tmps:
            _write(tmps, ("new A", "new B"))
    assert calls[:2] == [str(a), str(b)]  # the first was in place when the second failed
    assert _files(tmp_path) == before  # and nothing else is left: no temporary, no copy


def test_signals_wait_until_the_set_is_in_place(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    if not hasattr(signal, "SIGHUP"):
        pytest.skip("no SIGHUP here")
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    seen: list[str] = []
    real = os.replace

    def replace(src: Any, dst: Any, **kwargs: Any) -> None:
        if not seen:
            os.kill(os.getpid(), signal.SIGHUP)  # arrives between the two renames
        seen.append(f"renamed {Path(dst).name}")
        real(src, dst, **kwargs)

    previous = signal.signal(signal.SIGHUP, lambda *_: seen.append("signal"))
    try:
        monkeypatch.setattr(os, "replace", replace)
        with atomic_paths(a, b) as tmps:
            _write(tmps, ("A", "B"))
    finally:
        signal.signal(signal.SIGHUP, previous)
    assert seen == ["renamed a.txt", "renamed b.txt", "signal"]


def test_the_same_file_twice_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="the same file twice"):
        with atomic_paths(tmp_path / "a", tmp_path / "." / "a"):
            pass


# --------------------------------------------------------------------------- cell fit
@pytest.fixture
def trace(tmp_path: Path) -> Path:
    path = tmp_path / "trace.csv"
    gaps = 17.6 + np.random.default_rng(5).exponential(5.0, 200)
    path.write_text("interarrival_s\n" + "".join(f"{v:.6f}\n" for v in gaps))
    return path


def _fit(trace: Path, *extra: str) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(["fit", str(trace), "--families", "expon,gamma", *extra])
    return code, err.getvalue()


def test_fit_writes_its_yaml_and_png_together(trace: Path) -> None:
    out = trace.parent / "fit" / "arrivals.yaml"
    out.parent.mkdir()
    code, err = _fit(trace, "--out", str(out))  # warnings of the fit's own (200 exponential gaps) aside
    assert code == 0 and "cell: error" not in err
    assert out.read_text().startswith("# fitted by `cell fit`")
    assert (out.parent / "arrivals.png").read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in out.parent.iterdir()) == ["arrivals.png", "arrivals.yaml"]


@pytest.mark.parametrize("old", [False, True], ids=["new pair", "old pair"])
@pytest.mark.parametrize("fail", ["second rename", "yaml write"])
def test_fit_failing_on_its_second_file_leaves_nothing(trace: Path, monkeypatch: pytest.MonkeyPatch,
                                                       old: bool, fail: str) -> None:
    folder = trace.parent / "fit"
    folder.mkdir()
    out, figure = folder / "arrivals.yaml", folder / "hist.png"
    if old:
        out.write_text("arrivals: {distribution: expon}\n")
        figure.write_bytes(PNG_MAGIC + b"old")
    before = _files(folder)
    full = OSError(errno.ENOSPC, "No space left on device")
    if fail == "second rename":
        calls = _replace_failing_at(monkeypatch, 2, full, folder)
    else:
        real_write: Callable[..., int] = Path.write_text
        calls = []

        def write_text(self: Path, *args: Any, **kwargs: Any) -> int:
            if self.name.startswith(".arrivals.yaml.cell-"):
                raise full
            return real_write(self, *args, **kwargs)

        monkeypatch.setattr(Path, "write_text", write_text)
    code, err = _fit(trace, "--out", str(out), "--figure", str(figure))
    assert code != 0 and err.count("\n") == 1 and "no space left on device" in err, err
    assert str(out) in err or str(figure) in err, err
    assert calls[:1] in ([], [str(figure)])  # when the YAML failed, the figure was not yet in place
    assert _files(folder) == before
