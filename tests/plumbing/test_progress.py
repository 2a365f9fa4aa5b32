"""``cell.plumbing.progress``: a bar on a terminal, whole occasional lines in a log."""

from __future__ import annotations

import io
import re

import pytest

from cell.plumbing.progress import Progress, progress

LINE = re.compile(r"^sweep: ([\d,]+)/([\d,]+) replications \((\d+) %\), ([\d.]+) s elapsed, "
                  r"~(\d+) s left$")
LAST = re.compile(r"^sweep: ([\d,]+)/([\d,]+) replications \(100 %\), done in ([\d.]+) s$")


class Clock:
    """A clock the test moves: ``step`` seconds per reading after each unit of work."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def run(total: int, seconds_each: float, stream: io.StringIO) -> None:
    clock = Clock()
    with Progress(total, "sweep", "replications", file=stream, clock=clock) as bar:
        for _ in range(total):
            clock.now += seconds_each
            bar.update()


def test_a_log_gets_a_whole_line_every_tenth_and_one_at_the_end() -> None:
    out = io.StringIO()
    run(2800, 0.003, out)
    text = out.getvalue()
    assert "\r" not in text and text.endswith("\n")
    lines = text.splitlines()
    assert len(lines) == 10
    for k, line in enumerate(lines[:-1], start=1):
        m = LINE.match(line)
        assert m, line
        done, total, pct = int(m[1].replace(",", "")), int(m[2].replace(",", "")), int(m[3])
        assert (done, total, pct) == (280 * k, 2800, 10 * k)
        elapsed = float(m[4])
        assert elapsed == pytest.approx(0.003 * done, abs=0.05)
        assert int(m[5]) == round(0.003 * (total - done))     # the same pace to the end
    last = LAST.match(lines[-1])
    assert last and last[1] == last[2] == "2,800" and float(last[3]) == pytest.approx(8.4)


def test_a_slow_run_still_reports_every_half_minute() -> None:
    out = io.StringIO()
    run(100, 12.0, out)                     # a tenth takes 120 s
    elapsed = [float(LINE.match(line)[4]) for line in out.getvalue().splitlines()[:-1]]
    gaps = [b - a for a, b in zip([0.0, *elapsed], elapsed)]
    assert len(elapsed) > 30 and max(gaps) <= 30.0 + 12.0


def test_a_long_run_logs_a_few_lines_not_a_wall_of_carriage_returns() -> None:
    out = io.StringIO()
    run(100_000, 1e-5, out)
    assert len(out.getvalue()) < 1000 and len(out.getvalue().splitlines()) == 10


def test_a_terminal_gets_a_tqdm_bar() -> None:
    from tqdm import tqdm

    out = Terminal()
    bar = Progress(50, "sweep", "replications", file=out)
    assert isinstance(bar.bar, tqdm) and not bar.lines
    for _ in range(50):
        bar.update()
    bar.close()
    text = out.getvalue()
    assert text.startswith("\rsweep:") and "replications/s" in text and "elapsed" not in text


def test_disabled_or_empty_shows_nothing() -> None:
    for stream, total, enabled in ((io.StringIO(), 10, False), (Terminal(), 10, False),
                                   (io.StringIO(), 0, True)):
        with Progress(total, "sweep", "replications", file=stream, enabled=enabled) as bar:
            for _ in range(total):
                bar.update()
        assert stream.getvalue() == ""


def test_an_unfinished_run_does_not_claim_to_be_done() -> None:
    out = io.StringIO()
    clock = Clock()
    with Progress(10, "sweep", "replications", file=out, clock=clock) as bar:
        for _ in range(4):
            clock.now += 1.0
            bar.update()
    assert "done" not in out.getvalue() and len(out.getvalue().splitlines()) == 4


def test_progress_yields_every_item_in_order() -> None:
    out = io.StringIO()
    assert list(progress(range(7), "frames", "frames", file=out)) == list(range(7))
    assert out.getvalue().splitlines()[-1].startswith("frames: 7/7 frames (100 %), done in ")
