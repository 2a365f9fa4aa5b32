"""Permissions that hold (issue 25, item 4): a restrictive umask, a read-only HOME or
XDG_CACHE_HOME, a read-only output parent.  Each case: one clean line and exit 2, or a correct
run, and nothing left behind.

Root (as these tests often run) is not held to permission bits, so each command runs without
them: as root, under ``setpriv`` with every capability dropped (CAP_DAC_OVERRIDE above all:
root is then held to the bits as any user is, while still reaching the interpreter in its
own folders); as another user, as it is.  Skipped where neither can be had.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from cell.scenario import catalog
from tests.prose import in_order

BASELINE = str(catalog.path("baseline"))
SETPRIV = ["setpriv", "--inh-caps=-all", "--bounding-set=-all"]


def _unprivileged_prefix(probe: Path) -> list[str] | None:
    """The command prefix that runs a program held to permission bits, or None."""
    if os.geteuid() != 0:
        return []
    if shutil.which("setpriv") is None:
        return None
    probe.mkdir(mode=0o555)
    try:
        p = subprocess.run([*SETPRIV, sys.executable, "-c",
                            f"open({str(probe / 'x')!r}, 'w')"], capture_output=True, timeout=60)
    except OSError:
        return None
    finally:
        with_rights = probe.stat().st_mode
        probe.chmod(0o755)
        shutil.rmtree(probe)
    return SETPRIV if p.returncode != 0 and with_rights else None


def _held(base: Path):
    """Run ``python -m cell ARGS`` held to permission bits, with ``umask``, in ``base/w``, its
    HOME ``base/w/home`` and TMPDIR ``base/w/tmp`` unless ``env`` says otherwise."""
    prefix = _unprivileged_prefix(base / "probe")
    if prefix is None:
        pytest.skip("no way to run without root's permission override (setpriv)")
    work = base / "w"
    (work / "home").mkdir(parents=True)
    (work / "tmp").mkdir()

    def run(args, umask: int = 0o022, env=None, code: str | None = None):
        environ = {**os.environ, "HOME": str(work / "home"), "TMPDIR": str(work / "tmp"),
                   "XDG_CACHE_HOME": "", "XDG_CONFIG_HOME": "", "MPLCONFIGDIR": "",
                   **(env or {})}
        command = [sys.executable, "-c", code] if code else [sys.executable, "-m", "cell", *args]
        return subprocess.run([*prefix, *command], cwd=work, env=environ, capture_output=True,
                              text=True, timeout=300, preexec_fn=lambda: os.umask(umask))
    run.work = work
    return run


@pytest.fixture
def held(tmp_path):
    return _held(tmp_path)


#: Several commands in one process (one interpreter start-up), each through cell.cli.main as
#: ``python -m cell`` runs it: its exit code, stdout and stderr, as JSON on stdout at the end.
SEVERAL = """
import contextlib, io, json, sys
from cell.cli.main import main
said = []
for argv in json.loads(sys.argv[1]):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        said.append((main(argv), out.getvalue(), err.getvalue()))
print(json.dumps(said))
"""


def _tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def _lines(err: str) -> list[str]:
    return [x for x in err.splitlines() if "%)" not in x]  # progress lines aside


UMASK_CASES = {
    "run": (["run", BASELINE, "--set", "run.parts=20", "--out", "o"], "o"),
    "sweep": (["sweep", "SWEEP", "--out", "s", "--workers", "1"], "s"),
    "compare": (["compare", BASELINE, "non_adaptive", "--set", "run.parts=20", "--replications",
                 "2", "--workers", "1"], "cell compare's temporary folder"),
    "fit": (["fit", "TRACE", "--out", "fit.yaml"], "fit.yaml"),
    "path": (["path", BASELINE, "--out", "p/path.csv"], "p/path.csv"),
}


@pytest.fixture(scope="module")
def umask_0777(tmp_path_factory):
    """Every command of UMASK_CASES under umask 0777, in one process held to permission bits:
    each one's (exit code, stdout, stderr), and the folder's tree before and after them all."""
    held = _held(tmp_path_factory.mktemp("umask"))
    w = held.work
    (w / "sweep.yaml").write_text(f"base: {BASELINE}\ngrid: {{run.parts: [20, 21]}}\n"
                                  "replications: 2\n")
    (w / "trace.csv").write_text("interarrival_s\n" + "\n".join(
        str(20 + i % 5) for i in range(30)) + "\n")
    argvs = [[str(w / "sweep.yaml") if a == "SWEEP" else str(w / "trace.csv") if a == "TRACE"
              else a for a in args] for args, _ in UMASK_CASES.values()]
    before = _tree(w)
    p = held([], umask=0o777, code=SEVERAL.replace("json.loads(sys.argv[1])", repr(argvs)))
    assert (p.returncode, p.stderr) == (0, ""), p.stderr
    said = json.loads(p.stdout.splitlines()[-1])
    return dict(zip(UMASK_CASES, said)), before, _tree(w)


@pytest.mark.parametrize("name", list(UMASK_CASES))
def test_umask_0777_is_one_line_and_leaves_nothing(umask_0777, name):
    said, before, after = umask_0777
    code, _, err = said[name]
    assert code == 2, err
    (line,) = _lines(err)
    names = UMASK_CASES[name][1]
    what = "a file" if "." in names.rsplit("/", 1)[-1] else "a folder"  # the thing it could not use
    assert in_order(line, f"cell: error: {names}: ", "umask 0777", what, "umask 022"), err
    assert after == before  # no output, no staging, no cache or matplotlib folder, of any of them


def test_umask_0777_still_runs_a_command_that_writes_nothing(held):
    p = held(["scenarios"], umask=0o777)
    assert p.returncode == 0 and p.stderr == "" and "baseline" in p.stdout
    assert _tree(held.work) == ["home", "tmp"]


def test_a_cache_that_cannot_be_written_leaves_no_folder(held):
    """Under umask 0777 the cache's folder is made without its owner's rights: the entry
    cannot be written, and the folder made for it is removed."""
    cache = held.work / "cache"
    p = held([], umask=0o777, code="from cell.plumbing import cache; cache.store('t', [1], 2); "
                                   "print(cache.stored('t', [1]))",
             env={"XDG_CACHE_HOME": str(cache)})
    assert p.returncode == 0 and p.stdout == "None\n", p.stderr
    assert not cache.exists()


def test_a_read_only_home_and_cache_give_a_whole_run_and_no_word(held):
    home, cache = held.work / "ro-home", held.work / "ro-cache"
    for folder in (home, cache):
        folder.mkdir(mode=0o555)
    p = held(["run", BASELINE, "--set", "run.parts=20", "--out", "o"],
             env={"HOME": str(home), "XDG_CACHE_HOME": str(cache)})
    assert p.returncode == 0, p.stderr
    assert p.stderr == ""  # no library's warning about its cache or configuration
    assert sorted(x.name for x in (held.work / "o").iterdir()) == ["belts.csv", "parts.csv",
                                                                  "summary.csv"]
    assert list(home.iterdir()) == list(cache.iterdir()) == []
    assert list((held.work / "tmp").iterdir()) == []


def test_a_read_only_output_parent_is_one_line(held):
    ro = held.work / "ro"
    ro.mkdir(mode=0o555)
    p = held(["run", BASELINE, "--set", "run.parts=20", "--out", str(ro / "o")])
    assert p.returncode == 2
    (line,) = _lines(p.stderr)
    assert in_order(line, f"cell: error: {ro / 'o'}: ", f"write in {ro}:", "permission denied")
    assert list(ro.iterdir()) == [] and list((held.work / "tmp").iterdir()) == []
