"""``cell optimize STUDY --out DIR [--workers N] [--scheduler ADDR] [--resume]``."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.cli.common import check_workers, workers_argument

if TYPE_CHECKING:
    from cell.experiments.study import Study

HELP = "search scenario keys for the best setting (Optuna), then select it (KN)"
DESCRIPTION = ("Search a study file's keys with Optuna (TPE for one objective, NSGA-II for "
               "several), each trial replicated over common random numbers, under the study's "
               "constraints; the study is kept in DIR/study.db (--resume continues it). Then "
               "re-run the best few through Kim & Nelson's KN and write trials.csv, best.csv or "
               "front.csv, selection.csv, figures and report.md.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("study", help="study YAML file, or a built-in one by name (optimize)")
    p.add_argument("--out", required=True, help="directory for the study and its results")
    workers_argument(p, default="1")  # args.workers or 1, below
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the trials on a dask.distributed cluster at ADDRESS (DIR on a "
                        "disk its workers share)")
    p.add_argument("--resume", action="store_true", help="continue the study in --out")


def main(args: argparse.Namespace) -> int:
    from cell.experiments.study import load_study
    from cell.plumbing.output.atomic import OutputDir
    from cell.reporting.optimize_report import FILES

    out = OutputDir.check(args.out, ("study.db", "study.db-journal", *FILES))
    check_workers(args.workers, args.scheduler)
    from cell.scenario import catalog

    study = load_study(catalog.resolve(args.study))  # every problem before anything is written
    if study.settings.select is not None and study.settings.select.n0 > study.settings.select.max:
        from cell.plumbing.errors import ScenarioError

        raise ScenarioError(args.study, "select.n0", study.settings.select.n0, "above select.max")
    if not study.settings.objectives:
        from cell.plumbing.errors import ScenarioError

        raise ScenarioError(args.study, "objectives", [], "name at least one {measure, goal}")
    from cell.experiments.optimize import check_storage, connect, open_study, run_workers

    check_storage(study, out, args.resume)  # a foreign or damaged study.db: never written into
    client = None
    if args.scheduler is not None:
        from cell.experiments.sweep.cluster import CONNECT_TIMEOUT_S

        print(f"connecting to the dask scheduler at {args.scheduler} (giving up after "
              f"{CONNECT_TIMEOUT_S:g} s)", file=sys.stderr)
        client = connect(args.scheduler)  # unreachable: one line, before anything is written
    try:
        out.mkdir(parents=True, exist_ok=True)
        o = open_study(study, out, args.resume)
    except BaseException:
        if client is not None:
            client.close()
        raise
    from cell.experiments.optimize import counted
    from cell.plumbing.progress import Progress

    done = counted(o, running=False)
    bar = Progress(study.settings.trials, f"optimize {study.name}", "trials")
    bar.update(done)
    try:  # Ctrl-C and kill: cell.cli.main's handlers (KeyboardInterrupt, Terminated)
        run_workers(study, out, o, args.workers or 1, client, bar)
    except KeyboardInterrupt as exc:
        from cell.plumbing.interrupts import stopped_by

        bar.close()
        kept = counted(o, running=False)
        print(f"cell optimize: stopped; {kept} finished trial{'s' if kept != 1 else ''} kept in "
              f"{out / 'study.db'}: the same command with --resume runs only the rest",
              file=sys.stderr)
        return stopped_by(exc, None)[0]  # 130 or 143, and main says its line
    bar.close()
    shown = shlex.quote(catalog.shown(study.source))
    written = write_results(study, o, out, f"cell optimize {shown} --out ...")
    print(f"wrote {out}: " + ", ".join(Path(p).name for p in written))
    return 0


def write_results(study: Study, o: Any, out: Path, command: str) -> list[Path]:
    from cell.experiments.optimize import SELECT_OFFSET
    from cell.experiments.selection import select_scenarios, verdicts
    from cell.plumbing.output.atomic import atomic_paths, float_formatter
    from cell.reporting.optimize_report import (
        candidates,
        figures,
        importances,
        label,
        markdown,
        selection_measure,
        trials_frame,
    )

    frame = trials_frame(study, o)
    picked = candidates(study, frame)
    sel = None
    s = study.settings.select
    names = ["trials.csv", "front.csv" if len(study.settings.objectives) > 1 else "best.csv",
             "history.png", "front.png", "importance.png", "report.md"]
    if picked and s is not None:
        m, up = selection_measure(study)
        scen = [study.scenario({p.key: frame.loc[i, p.key] for p in study.params}) for i in picked]
        sel = select_scenarios(scen, m, up, s.delta, s.pcs, s.n0, s.max,
                               lambda r: study.stream(r, SELECT_OFFSET),
                               labels=[label(study, frame.loc[i]) for i in picked],
                               where=f"{study.source}: select.measure = {m}")
        names.insert(2, "selection.csv")
    imp = importances(study, o)
    fmt = float_formatter()
    with atomic_paths(*(out / n for n in names)) as tmps:
        files = dict(zip(names, tmps))
        frame.to_csv(files["trials.csv"], index=False, float_format=fmt, lineterminator="\n")
        best = frame[frame["on_front"]] if len(frame) else frame
        best.to_csv(files[names[1]], index=False, float_format=fmt, lineterminator="\n")
        if sel is not None:
            import pandas as pd

            words = verdicts(sel)
            pd.DataFrame({"candidate": [label(study, frame.loc[i]) for i in picked],
                          "trial": [int(frame.loc[i, "trial"]) for i in picked],
                          "mean": sel.means, "replications": sel.counts, "verdict": words}) \
                .to_csv(files["selection.csv"], index=False, float_format=fmt, lineterminator="\n")
        if len(frame):
            figures(study, o, frame, files)
        else:
            for n in ("history.png", "front.png", "importance.png"):
                files[n].write_bytes(b"")
        files["report.md"].write_text(markdown(study, frame, picked, sel, imp, command),
                                      encoding="utf-8")
    return [out / n for n in names]
