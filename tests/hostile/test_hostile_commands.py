"""Every command's outputs and options, the one place at the top, and real subprocesses.

Outputs that cannot be written are refused before any work (the work is replaced by a
function that fails the test if it runs), in one line naming the path; a disk that fills
while the output is written leaves the old output as it was; the failures that only the
top can catch (memory, recursion, the system refusing a write, usage errors) are one
line and exit 2; an unexpected exception keeps its traceback.
"""

from __future__ import annotations

import errno
import importlib
import os
import pkgutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from .harness import Result, case, cli, ran_sanely, refused, tree

ROOT = Path(__file__).resolve().parents[2]
TRACE = "interarrival_s\n" + "".join(f"{22 + (i * 7919 % 13) / 5:.3f}\n" for i in range(60))

#: command -> (arguments before --out, the dotted path of the work it must not start, kind of output)
COMMANDS: dict[str, tuple[list[str], str, str]] = {
    "run": (["run", "baseline", "--set", "run.parts=3"], "cell.scenario.schema.load_scenario", "dir"),
    "path": (["path", "baseline"], "cell.scenario.schema.load_scenario", "file"),
    "mintime": (["mintime", "mintime_kinematic", "--set", "mintime.grid_points=30"],
                "cell.scenario.schema.load_scenario", "dir"),
    "figures": (["figures"], "cell.scenario.schema.load_scenario", "dir"),
    "animate": (["animate", "baseline", "--parts", "1"], "cell.scenario.schema.load_scenario", "file.gif"),
    "bench": (["bench"], "cell.bench.throughput.benchmarks", "file"),
    "schema": (["schema"], "cell.scenario.schema.json_schema", "file"),
    "fit": (["fit", "{trace}"], "cell.experiments.fit.column.read_column", "file.yaml"),
}


#: Other words a command's refusal may use (animate checks the suffix first, fit the directory).
OR = {"animate": (".gif or .mp4",), "fit": ("its directory does not exist",)}
#: The commands through which every condition of the shared output checks is walked: ``run``
#: for OutputDir, ``path`` for check_file; the others wire the same check, one case each.
WALKED = ("run", "path")


def _import_everything() -> None:
    """Every module of the package imported now, so that none binds a forbidden stand-in by
    ``from ... import`` while it is patched in."""
    import cell

    for module in pkgutil.walk_packages(cell.__path__, "cell."):
        if not module.name.endswith("__main__"):
            importlib.import_module(module.name)


def _forbid(monkeypatch: pytest.MonkeyPatch, dotted: str) -> None:
    _import_everything()

    def work(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError(f"{dotted} ran before the output was checked")

    monkeypatch.setattr(dotted, work)


def _argv(command: str, tmp: Path) -> list[str]:
    trace = tmp / "trace.csv"
    trace.write_text(TRACE)
    return [a.replace("{trace}", str(trace)) for a in COMMANDS[command][0]]


def _targets(tmp: Path, kind: str) -> list[tuple[str, str, Path | str, str]]:
    """(id, how it is made, --out, words of the refusal)."""
    suffix = kind.partition(".")[2]
    name = f"out.{suffix}" if suffix else "out"
    blocker = tmp / "a_file"
    blocker.write_text("mine\n")
    foreign = tmp / "holds_mine"
    foreign.mkdir(exist_ok=True)
    (foreign / "thesis.docx").write_text("mine\n")
    folder = tmp / "a_dir"
    folder.mkdir(exist_ok=True)
    cases: list[tuple[str, str, Path | str, str]] = [
        ("empty", "", "", "an empty path"),
        ("a dash", "", "-", "no cell command writes to standard output"),
        ("under a file", "", blocker / name, "not a directory"),
        ("name too long", "", tmp / ("n" * 250 + (f".{suffix}" if suffix else "")), "file name too long"),
        ("path too long", "", tmp.joinpath(*["d" * 200] * 25) / name, "too long"),
        ("read-only file system", "rofs", tmp / "ro" / name, "read-only file system"),
        ("permission denied", "noaccess", tmp / "locked" / name, "permission denied"),
        ("newline in the name", "", blocker / f"a\nb{name}", "not a directory"),
    ]
    if kind == "dir":
        cases += [("an existing file", "", blocker, "is a file"),
                  ("a directory of the user's", "", foreign, "holds files this command does not write"),
                  ("the current directory", "", ".", "holds the current directory")]
    else:
        cases += [("an existing directory", "", folder, "is a directory")]
    return cases


def _fake_readonly(monkeypatch: pytest.MonkeyPatch, where: Path) -> None:
    real = os.statvfs

    class ReadOnly:
        def __init__(self, real_result: Any):
            self.real = real_result
            self.f_flag = real_result.f_flag | os.ST_RDONLY

        def __getattr__(self, name: str) -> Any:
            return getattr(self.real, name)

    monkeypatch.setattr(os, "statvfs", lambda p: ReadOnly(real(p)) if Path(p) == where else real(p))


def _fake_noaccess(monkeypatch: pytest.MonkeyPatch, where: Path) -> None:
    real = os.access
    monkeypatch.setattr(os, "access",
                        lambda p, mode, **kw: False if Path(p) == where else real(p, mode, **kw))


@pytest.mark.parametrize("command", list(COMMANDS))
def test_outputs_refused_before_any_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                         command: str) -> None:
    argv, work, kind = COMMANDS[command]
    argv = _argv(command, tmp_path)
    monkeypatch.chdir(tmp_path)
    failures = []
    targets = _targets(tmp_path, kind)
    for label, how, out, words in targets if command in WALKED else [
            t for t in targets if t[0] == "under a file"]:
        with monkeypatch.context() as m:
            _forbid(m, work)
            if how:
                Path(out).parent.mkdir()
                (_fake_readonly if how == "rofs" else _fake_noaccess)(m, Path(out).parent)
            shown = Path(out) if str(out) else None
            before = tree(shown) if shown is not None else None
            res = cli(*argv, "--out", out)
            try:
                line = refused(res, nothing_in=shown if shown is not None and shown != Path(".") else None,
                               before=before)
                assert any(w in line for w in (words, *OR.get(command, ()))), line
            except AssertionError as exc:
                failures.append(f"{label}: {exc}"[:1200])
    assert not failures, "\n".join(failures)


def _enospc(*args: Any, **kwargs: Any) -> Any:
    raise OSError(errno.ENOSPC, "No space left on device")


class _FillingFile:
    """A file whose writes fail with ENOSPC once ``room`` bytes are written."""

    def __init__(self, stream: Any, room: int):
        self.stream, self.room = stream, room

    def write(self, data: Any) -> int:
        self.room -= len(data)
        if self.room < 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        return self.stream.write(data)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)

    def __enter__(self) -> _FillingFile:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stream.close()


@pytest.mark.parametrize("command", ["run", "path", "schema", "fit"])
def test_disk_full_while_writing_keeps_the_old_output(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                      command: str) -> None:
    """The disk fills after the work, a few hundred bytes in: one line naming the output, and the
    output of the previous run unchanged, nothing else left (the first byte's failure meets the
    same clean-up; mintime commits through the same OutputDir as run)."""
    room = 300
    import cell.plumbing.output.atomic

    argv = _argv(command, tmp_path)
    kind = COMMANDS[command][2]
    out = tmp_path / ("old" if kind == "dir" else "old." + (kind.partition(".")[2] or "txt"))
    assert cli(*argv, "--out", out).code == 0
    before = tree(out)
    real_open = cell.plumbing.output.atomic._open
    monkeypatch.setattr(cell.plumbing.output.atomic, "_open",
                        lambda *a, **k: _FillingFile(real_open(*a, **k), room))
    if command == "fit":  # the figure is drawn by matplotlib, not through cell.plumbing.output.atomic
        monkeypatch.setattr("matplotlib.figure.Figure.savefig", _enospc)
    again = ["--force"] if command == "run" else []  # cell run keeps another run's files without it
    refused(cli(*argv, "--out", out, *again), "old", "no space left on device", nothing_in=out,
            before=before)


def test_run_force_never_replaces_a_directory_of_the_users(tmp_path: Path) -> None:
    """--force replaces the files a run writes, never a directory that has one's name (it
    deleted the user's folder and what it held): refused, naming it, before any work."""
    out = tmp_path / "old"
    (out / "parts.csv").mkdir(parents=True)
    (out / "parts.csv" / "mine.txt").write_text("the user's own data\n")
    (out / "summary.csv").write_text("scenario\nan earlier run\n")
    before = tree(out)
    refused(cli(*COMMANDS["run"][0], "--out", out, "--force"), str(out), "parts.csv",
            nothing_in=out, before=before)


def test_figures_disk_full_keeps_the_old_set(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A figure set whose last PNG meets a full disk: the old set stays whole (drawing stubbed)."""
    import cell.reporting.figures.thesis_figures
    from cell.reporting.figures.style import save

    def fake(scenario: Any, out: Path, progress: Any = None, **kw: Any) -> list[Path]:
        from matplotlib.figure import Figure

        written = []
        for i, stem in enumerate(list(cell.reporting.figures.thesis_figures.FILES.values())[:3]):
            if i == 2:
                monkeypatch.setattr(Figure, "savefig", _enospc)
            written.append(save(Figure(), Path(out) / f"{stem}.png"))
        return written

    out = tmp_path / "figs"
    out.mkdir()
    (out / "fig08_working_environment.png").write_bytes(b"old")
    before = tree(out)
    monkeypatch.setattr(cell.reporting.figures.thesis_figures, "make_figures", fake)
    refused(cli("figures", "--out", out), "no space left on device", nothing_in=out, before=before)


# --- the one place at the top -----------------------------------------------------------------

def _raising(exc: BaseException) -> Any:
    def main(args: Any) -> int:
        raise exc

    return main


@pytest.mark.parametrize("exc,words", [
    (MemoryError(), ("cell run: ran out of memory", "run.parts")),
    (RecursionError("maximum recursion depth exceeded"), ("recursion limit",)),
    (PermissionError(errno.EACCES, "Permission denied", "/data/out/parts.csv"),
     ("/data/out/parts.csv: permission denied",)),
    (OSError(errno.ENOSPC, "No space left on device"), ("OUT: cannot write: no space left on device",)),
    (OSError(errno.ENAMETOOLONG, "File name too long", "/x/" + "n" * 400), ("file name too long", "…")),
    (OSError(errno.EISDIR, "Is a directory", "a\nb"), ("'a\\nb': is a directory",)),
], ids=lambda v: type(v).__name__ if isinstance(v, BaseException) else None)
def test_the_top_turns_anticipated_failures_into_one_line(monkeypatch: pytest.MonkeyPatch, exc: BaseException,
                                                           words: tuple[str, ...]) -> None:
    import cell.cli.run

    monkeypatch.setattr(cell.cli.run, "main", _raising(exc))
    refused(cli("run", "baseline", "--out", "OUT"), *words)


def test_a_real_memory_error_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """numpy refusing a 2**45-element array (256 TiB), inside the simulation."""
    import numpy as np

    import cell.sim.simulation

    monkeypatch.setattr(cell.sim.simulation, "simulate", lambda *a, **k: np.ones(2**45))
    out = tmp_path / "out"
    refused(cli("run", "baseline", "--out", out), "ran out of memory", nothing_in=out)


@pytest.mark.parametrize("exc", [ZeroDivisionError("a bug"), OSError(errno.EBADF, "a bug")])
def test_an_unexpected_exception_keeps_its_traceback(monkeypatch: pytest.MonkeyPatch,
                                                     exc: BaseException) -> None:
    import cell.cli.run

    monkeypatch.setattr(cell.cli.run, "main", _raising(exc))
    with pytest.raises(type(exc)):
        cli("run", "baseline", "--out", "OUT")


@pytest.mark.parametrize("argv,words", [
    ([], ("required",)),
    (["nosuch"], ("invalid choice",)),
    (["run", "baseline"], ("--out",)),
    (["sweep", "x", "--out", "y", "--workers", "many"], ("--workers", "many")),
    (["run", "baseline", "--out", "x", "--frobnicate"], ("unrecognized arguments",)),
])
def test_usage_errors_are_one_line(argv: list[str], words: tuple[str, ...]) -> None:
    line = refused(cli(*argv), *words)
    assert "--help" in line


def test_help_and_version_exit_0(capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (["--help"], ["--version"]):
        res = cli(*argv)
        assert res.code == 0 and res.out and res.err == ""     # a case checked otherwise


# --- options ---------------------------------------------------------------------------------

@pytest.mark.parametrize("option,value,words", [
    ("--parts", "0", "between 1 and 10000"), ("--parts", "1000000", "between"),
    ("--from-part", "0", "between"), ("--from-part", "100000000", "between"),
    ("--speed", "0", "between"), ("--speed", "nan", "between"), ("--speed", "inf", "between"),
    ("--fps", "0", "between"), ("--fps", "100000", "between"),
    ("--dpi", "0", "between"), ("--dpi", "1e6", "between"), ("--dpi", "nan", "between"),
    ("--parts", "10000", "frames"),
])
def test_animate_options_refused_before_simulating(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                   option: str, value: str, words: str) -> None:
    _forbid(monkeypatch, "cell.reporting.animation.movie.simulate_scenes")
    out = tmp_path / "a.gif"
    refused(cli("animate", "baseline", option, value, "--out", out), option, words, nothing_in=out)


@pytest.mark.parametrize("out", ["a.GIF.bak"])  # a.txt and a: the same suffix rule
def test_animate_suffixes(tmp_path: Path, out: str) -> None:
    refused(cli("animate", "baseline", "--out", tmp_path / out), ".gif or .mp4", nothing_in=tmp_path / out)


@pytest.mark.parametrize("name,text,words", [
    ("empty.csv", "", "empty"),
    ("binary.csv", "\x00\x01\x02", "binary"),
    ("nocol.csv", "a,b\n1,2\n", "interarrival_s"),
    ("negative.csv", "interarrival_s\n" + "-1\n" * 30, "interarrival_s"),
    ("text.csv", "interarrival_s\n" + "abc\n" * 30, "interarrival_s"),
    ("one.csv", "interarrival_s\n22.5\n", "interarrival_s"),
    ("equal.csv", "interarrival_s\n" + "22.5\n" * 30, "interarrival_s"),
    ("inf.csv", "interarrival_s\n" + "inf\n" * 30, "interarrival_s"),
])
def test_fit_hostile_traces(tmp_path: Path, name: str, text: str, words: str) -> None:
    trace = tmp_path / name
    trace.write_text(text)
    out = tmp_path / "fit.yaml"
    refused(cli("fit", trace, "--out", out), str(trace), words, nothing_in=out)
    assert not (tmp_path / "fit.png").exists()


@pytest.mark.parametrize("families,words", [("bogus", "bogus"), ("", "--families"), ("norm", "non-negative")])
def test_fit_hostile_families(tmp_path: Path, families: str, words: str) -> None:
    trace = tmp_path / "trace.csv"
    trace.write_text(TRACE)
    out = tmp_path / "fit.yaml"
    refused(cli("fit", trace, "--families", families, "--out", out), words, nothing_in=out)


def test_fit_refuses_to_overwrite_its_trace(tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    trace.write_text(TRACE)
    before = tree(trace)
    refused(cli("fit", trace, "--out", trace), "overwrite the trace", nothing_in=trace, before=before)
    refused(cli("fit", trace, "--out", tmp_path / "a.yaml", "--figure", trace), "overwrite", nothing_in=trace,
            before=before)


def test_mintime_old_stem_form_refused(tmp_path: Path) -> None:
    name = "m.csv"  # m.json: the same rule
    refused(cli("mintime", "baseline", "--out", tmp_path / name), "profile.csv and summary.json",
            nothing_in=tmp_path / name)


# --- real processes ----------------------------------------------------------------------------

def _subprocess(tmp: Path, *argv: str, code: str | None = None) -> Result:
    """``cell ARGV`` (or ``python -c CODE ARGV``) in a real process: one case of the suite."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    command = [sys.executable, "-c", code, *argv] if code else [sys.executable, "-m", "cell", *argv]
    proc = subprocess.run(command, capture_output=True, text=True, cwd=tmp, env=env, timeout=120)
    return Result(list(argv), proc.returncode, proc.stdout, proc.stderr, case("subprocess"))


SUBPROCESS_MEMORY = """
import sys, numpy
import cell.sim.simulation
cell.sim.simulation.simulate = lambda *a, **k: numpy.ones(2**45)
from cell.cli.main import main
sys.exit(main(sys.argv[1:]))
"""
SUBPROCESS_BUG = SUBPROCESS_MEMORY.replace("lambda *a, **k: numpy.ones(2**45)", "lambda *a, **k: 1 / 0")


def test_in_real_processes_no_traceback_escapes(tmp_path: Path) -> None:
    """A real process's top (``python -m cell``: main's code its exit code, nothing more said as
    it exits) for each kind of end: a refusal (a file that is not UTF-8; the same top for every
    refusal: a --set that is not YAML and an output under a file are refused in-process by
    test_hostile_yaml.py::test_hostile_set_values and test_outputs_refused_before_any_work) and
    a real MemoryError."""
    (tmp_path / "latin1.yaml").write_bytes(b"name: caf\xe9\n")
    (tmp_path / "a_file").write_text("x")
    cases = [
        (["run", "latin1.yaml", "--out", "o1"], None, "not UTF-8"),
        (["run", "baseline", "--out", "o5"], SUBPROCESS_MEMORY, "ran out of memory"),
    ]
    for argv, code, words in cases:
        refused(_subprocess(tmp_path, *argv, code=code), words)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "latin1.yaml"]


def test_in_a_real_process_a_bug_shows_its_traceback_and_good_input_runs(tmp_path: Path) -> None:
    bug = _subprocess(tmp_path, "run", "baseline", "--out", "o", code=SUBPROCESS_BUG)
    assert bug.code == 1 and "Traceback" in bug.err and "ZeroDivisionError" in bug.err
    assert not (tmp_path / "o").exists()
    good = _subprocess(tmp_path, "run", "baseline", "--set", "run.parts=3", "--out", "ok")
    ran_sanely(good, tmp_path / "ok", 3)
