"""``cell optimize``: search a study's keys with Optuna, over common random numbers.

One objective: TPE (Bergstra et al. 2011); several: NSGA-II (Deb et al. 2002); constraints
through Optuna's ``constraints_func`` (a trial is feasible when every value it returns is
<= 0).  The study lives in ``DIR/study.db`` (SQLite), so a killed run resumes from it and
several workers (local processes, or dask workers on a shared disk) share it.

Trial ``n`` samples with a sampler seeded from ``(seed, n)``, so with one worker a study's
trials depend on the seed and on the trials before them only: a run resumed after a kill
proposes what an unbroken one would.  Each trial runs ``replications`` replications of its
point on streams ``SeedSequence(seed, spawn_key=(r,))``, the same for every trial.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cell.experiments.study import Param, Study, interval, replicate
from cell.plumbing.errors import CellError

DB_NAME = "study.db"
#: Replications KN runs are drawn from these streams on: fresh ones, not the search's.
SELECT_OFFSET = 1_000_000


def storage_url(out: Path) -> str:
    return f"sqlite:///{(out / DB_NAME).resolve()}"


def fingerprint(study: Study) -> str:
    from cell import __version__

    doc = {"settings": study.settings.model_dump(mode="json", by_alias=True),
           "base": study.base.to_dict(), "version": __version__}
    return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()


def directions(study: Study) -> list[Any]:
    return [o.goal for o in study.settings.objectives]


def _sampler(study: Study, number: int) -> Any:
    import optuna

    seed = int(np.random.SeedSequence([study.settings.seed, number]).generate_state(1)[0])
    # Optuna 5 reads the constraints a trial sets itself (Trial.set_constraint); before it,
    # a constraints_func gave them
    given: dict[str, Any] = {} if _SET_CONSTRAINT else {"constraints_func": _constraints}
    if len(study.settings.objectives) > 1:
        return optuna.samplers.NSGAIISampler(seed=seed, **given)
    return optuna.samplers.TPESampler(seed=seed, n_startup_trials=min(10, max(2, study.settings.trials // 4)),
                                      **given)


def _has_set_constraint() -> bool:
    try:
        import optuna
    except ImportError:
        return False
    return hasattr(optuna.trial.Trial, "set_constraint")


_SET_CONSTRAINT = _has_set_constraint()


def _constraints(trial: Any) -> list[float]:
    return list(trial.user_attrs.get("excess", []))


#: The tables every Optuna storage holds: a database without them is not a study's.
OPTUNA_TABLES = frozenset({"studies", "study_directions", "study_user_attributes", "trials",
                           "version_info"})
#: What an SQLite database file starts with.
SQLITE_HEADER = b"SQLite format 3\x00"


def check_storage(study: Study, out: Path, resume: bool) -> None:
    """Refuse, before any work and writing nothing, a ``DIR/study.db`` that Optuna must not
    open: a directory or other non-file, a file that is not an SQLite database (or a damaged
    one), another program's database (without Optuna's tables), or a study database holding
    another study (another name, several, or this one's name with another fingerprint: the
    study file changed, or another version of cell); and any of them without ``resume``.
    Read through SQLite read-only, so that not even a journal is written."""
    import sqlite3
    import stat
    from urllib.parse import quote

    from cell.plumbing.errors import shown_path

    db = out / DB_NAME
    shown = shown_path(db)
    try:
        mode = os.stat(db).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise CellError(f"{shown}: cannot be read ({(exc.strerror or str(exc)).lower()})") from None
    if stat.S_ISDIR(mode):
        raise CellError(f"{shown}: a directory, not a study database; choose another --out")
    if not stat.S_ISREG(mode):
        raise CellError(f"{shown}: not a regular file, so not a study database; choose "
                        "another --out")
    if not resume:
        raise CellError(f"{out}: holds a study already ({DB_NAME}); add --resume to continue "
                        "it, or choose another --out")
    try:
        with open(db, "rb") as f:
            head = f.read(len(SQLITE_HEADER))
    except OSError as exc:
        raise CellError(f"{shown}: cannot be read ({(exc.strerror or str(exc)).lower()})") from None
    if head != SQLITE_HEADER:
        what = "empty" if not head else "not an SQLite database"
        raise CellError(f"{shown}: {what}, so not a study database; choose another --out")
    try:
        con = sqlite3.connect(f"file:{quote(str(db.resolve()))}?mode=ro", uri=True)
    except sqlite3.Error as exc:
        raise CellError(f"{shown}: cannot be opened as a database ({exc})") from None
    try:
        names = _stored_studies(con, study.name)
    except sqlite3.Error as exc:
        raise CellError(f"{shown}: a damaged database ({exc}); choose another --out") from None
    finally:
        con.close()
    if names is None:
        raise CellError(f"{shown}: another program's database (no Optuna study in it); "
                        "choose another --out")
    stored, mark = names
    if stored not in ([], [study.name]):  # (none: a run killed as it made its study)
        listed = ", ".join(repr(n) for n in stored[:3]) or "none"
        raise CellError(f"{shown}: holds another study ({listed}), not {study.name!r}; choose "
                        "another --out")
    if mark is not None and mark != fingerprint(study):
        raise CellError(f"{shown}: holds study {study.name!r} as another study file made it "
                        "(it changed since, or another version of cell ran it); choose another --out")


def _stored_studies(con: Any, name: str) -> tuple[list[str], str | None] | None:
    """The names of the studies in an Optuna database and the fingerprint stored with the one
    named ``name`` (None if it has none); None if the database is not Optuna's."""
    quick = con.execute("PRAGMA quick_check").fetchone()
    if quick is None or quick[0] != "ok":
        import sqlite3

        raise sqlite3.DatabaseError(quick[0] if quick else "no answer to its check")
    tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    if not OPTUNA_TABLES <= tables:
        return None
    stored = [r[0] for r in con.execute("SELECT study_name FROM studies ORDER BY study_id")]
    row = con.execute("SELECT a.value_json FROM study_user_attributes a JOIN studies s "
                      "ON a.study_id = s.study_id WHERE s.study_name = ? AND a.key = "
                      "'fingerprint'", (name,)).fetchone()
    mark = None
    if row is not None:
        try:
            mark = json.loads(row[0])
        except ValueError:
            mark = str(row[0])
    return stored, str(mark) if mark is not None else None


def open_study(study: Study, out: Path, resume: bool) -> Any:
    """The Optuna study in ``out``: new, or (``resume``) the one there, which must be this
    study's (:func:`check_storage`); trials a killed run left running are marked failed (and
    run again)."""
    import optuna

    check_storage(study, out, resume)  # (the command checked it before its work: again now)
    optuna.logging.set_verbosity(optuna.logging.ERROR)  # refused trials: in trials.csv, with the reason
    o = optuna.create_study(study_name=study.name, storage=storage_url(out), load_if_exists=True,
                            directions=directions(study))
    o.set_user_attr("fingerprint", fingerprint(study))
    for t in o.get_trials(deepcopy=False, states=(optuna.trial.TrialState.RUNNING,)):
        o._storage.set_trial_state_values(t._trial_id, optuna.trial.TrialState.FAIL)
    return o


def suggest(trial: Any, p: Param) -> Any:
    if p.is_choice:
        return p.choices[trial.suggest_categorical(p.key, list(range(len(p.choices))))]
    if p.whole:
        return trial.suggest_int(p.key, int(round(p.low)), int(round(p.high)), log=p.log,
                                 step=int(p.step or 1))
    return trial.suggest_float(p.key, p.low, p.high, log=p.log, step=p.step)


def measured(study: Study) -> list[str]:
    """The measures a trial records: the objectives', the constraints', the selection's, the
    headline ones and the study's ``measures:``."""
    keys = {p.key for p in study.params}
    names = [o.measure for o in study.settings.objectives if o.measure not in keys]
    names += [c.measure for c in study.constraints]
    if study.settings.select is not None and study.settings.select.measure:
        names.append(study.settings.select.measure)
    names += ["parts_missed", "spacing_outside_pct", "parts_per_hr_wallclock"]
    return list(dict.fromkeys(names + list(study.settings.measures)))


def evaluate(study: Study, trial: Any) -> tuple[float, ...]:
    """One trial: its point's replications; the objectives' means (a varied key: its value)."""
    from cell.plumbing.errors import ScenarioError

    values = {p.key: suggest(trial, p) for p in study.params}
    trial.set_user_attr("values", {k: _plain(v) for k, v in values.items()})
    try:
        rows = replicate(study, values, range(study.settings.replications))
    except ScenarioError as exc:
        trial.set_user_attr("refused", f"{exc.key} = {exc.value}: {exc.why}")
        raise
    names = measured(study)
    summary = {}
    for m in names:
        mean, half = interval([r[m] for r in rows])
        summary[m] = [mean, half]
    trial.set_user_attr("measures", summary)
    trial.set_user_attr("reps", {m: [r[m] for r in rows] for m in names})
    excess = [c.excess(summary[c.measure][0]) for c in study.constraints]
    trial.set_user_attr("excess", excess)
    if _SET_CONSTRAINT:
        for c, e in zip(study.constraints, excess):
            trial.set_constraint(str(c), e)
    out = []
    for o in study.settings.objectives:
        x = values[o.measure] if o.measure in values else summary[o.measure][0]
        out.append(float(x) if not math.isnan(float(x)) else math.inf)
    return tuple(out)


def _plain(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


def counted(o: Any, running: bool = True) -> int:
    """Trials that count towards ``trials``: complete, refused (a point whose scenario is
    refused is a finished trial), and with ``running`` those under way; not a trial a
    killed run left behind (marked failed on resume, and run again)."""
    import optuna

    states = optuna.trial.TrialState
    n = 0
    for t in o.get_trials(deepcopy=False):
        n += t.state == states.COMPLETE or running and t.state == states.RUNNING \
            or t.state == states.FAIL and "refused" in t.user_attrs
    return n


def work(study: Study, o: Any, on_trial: Callable[[], None] | None = None) -> int:
    """Run trials in this process until the study has its ``trials`` (counting every
    worker's, finished or running); returns how many this process ran."""
    from cell.plumbing.errors import ScenarioError

    ran = 0
    while (number := counted(o)) < study.settings.trials:
        o.sampler = _sampler(study, number)
        o.optimize(lambda t: evaluate(study, t), n_trials=1, catch=(ScenarioError,),
                   gc_after_trial=False)
        ran += 1
        if on_trial is not None:
            on_trial()
    return ran


def worker(source: str, out: str) -> int:
    """A worker process (local or on a dask cluster): load the study file and the study
    from the shared database, and run trials until there are enough."""
    import optuna

    from cell.experiments.study import load_study

    optuna.logging.set_verbosity(optuna.logging.ERROR)  # refused trials: in trials.csv, with the reason
    study = load_study(source, corners=False)
    o = optuna.load_study(study_name=study.name, storage=storage_url(Path(out)))
    return work(study, o)


def connect(scheduler: str) -> Any:
    """A client of the dask scheduler at ``scheduler``, or the one line that says why not
    (as ``cell sweep --scheduler`` says it: :func:`cell.experiments.sweep.cluster.connect`)."""
    from cell.experiments.sweep.cluster import connect as reach

    return reach(scheduler)


def run_workers(study: Study, out: Path, o: Any, workers: int, client: Any,
                progress: Any) -> None:
    """Run the trials: in this process (one worker), in local processes, or on the dask
    cluster of ``client`` (:func:`connect`; closed here)."""
    if client is None and workers <= 1:
        work(study, o, on_trial=progress.update)
        return
    import concurrent.futures as cf
    import time

    if client is not None:
        futures = [client.submit(worker, str(study.source.resolve()), str(out.resolve()),
                                 pure=False) for _ in range(max(workers, 1))]
        waiter: Callable[[], bool] = lambda: all(f.done() for f in futures)  # noqa: E731
    else:
        import multiprocessing

        pool = cf.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        jobs = [pool.submit(worker, str(study.source.resolve()), str(out.resolve()))
                for _ in range(workers)]
        waiter = lambda: all(j.done() for j in jobs)  # noqa: E731
    try:
        seen = counted(o, running=False)
        while not waiter():
            time.sleep(0.5)
            now = counted(o, running=False)
            progress.update(now - seen)
            seen = now
        progress.update(counted(o, running=False) - seen)
        for j in (futures if client is not None else jobs):
            j.result()
    finally:
        if client is not None:
            client.close()
        else:
            pool.shutdown(cancel_futures=True)
