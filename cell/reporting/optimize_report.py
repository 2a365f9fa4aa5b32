"""What ``cell optimize`` writes into DIR: trials.csv, best.csv (or front.csv), selection.csv,
history.png, front.png, importance.png and report.md, all together (cell.plumbing.output.atomic)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from cell.experiments.kn import Selection
from cell.experiments.optimize import SELECT_OFFSET, measured
from cell.experiments.study import Study
from cell.scenario.run_length import RunLength

FILES = ("trials.csv", "best.csv", "front.csv", "selection.csv", "history.png", "front.png",
         "importance.png", "report.md")


def trials_frame(study: Study, o: Any) -> Any:
    """One row per finished trial: its keys, each measure's mean and 95 % half-width, the
    constraints' verdict, and whether it is on the Pareto front (or the best)."""
    import optuna
    import pandas as pd

    states = optuna.trial.TrialState
    rows = []
    for t in sorted(o.get_trials(deepcopy=False), key=lambda t: t.number):
        if not (t.state == states.COMPLETE or "refused" in t.user_attrs):
            continue
        row: dict[str, Any] = {"trial": t.number}
        row.update(t.user_attrs.get("values", {}))
        for m, (mean, half) in t.user_attrs.get("measures", {}).items():
            row[m], row[f"{m}_ci95"] = mean, half
        excess = t.user_attrs.get("excess", [math.inf])
        row["feasible"] = t.state == states.COMPLETE and all(e <= 0 for e in excess)
        row["refused"] = t.user_attrs.get("refused", "")
        rows.append(row)
    frame = pd.DataFrame(rows)
    frame.insert(len(frame.columns) - 1, "on_front", _front(study, frame))
    return frame


def _objective_columns(study: Study) -> list[tuple[str, bool]]:
    return [(o.measure, o.goal == "maximize") for o in study.settings.objectives]


def _front(study: Study, frame: Any) -> list[bool]:
    """Feasible trials no other feasible trial beats in every objective (for one objective:
    the best, ties included)."""
    cols = _objective_columns(study)
    ok = [i for i in range(len(frame)) if frame["feasible"].iloc[i]]
    vals = {i: [(-1 if up else 1) * float(frame[c].iloc[i]) for c, up in cols] for i in ok}
    on = []
    for i in range(len(frame)):
        if i not in vals:
            on.append(False)
            continue
        a = vals[i]
        on.append(not any(all(x <= y for x, y in zip(vals[j], a)) and vals[j] != a for j in ok))
    return on


def candidates(study: Study, frame: Any) -> list[int]:
    """Rows KN re-runs: the front's (best first by the selection measure), up to
    ``select.candidates``, then the next best feasible ones."""
    sel = study.settings.select
    if sel is None or not len(frame):
        return []
    m, up = selection_measure(study)
    feasible = frame[frame["feasible"]]
    order = feasible.sort_values([m, "trial"], ascending=[not up, True])
    keys = [p.key for p in study.params]
    seen: set[tuple[str, ...]] = set()
    picked: list[int] = []
    for i in [i for i in order.index if frame.loc[i, "on_front"]] + \
            [i for i in order.index if not frame.loc[i, "on_front"]]:
        point = tuple(str(frame.loc[i, k]) for k in keys)  # a point the search tried twice: once
        if point not in seen and len(picked) < sel.candidates:
            seen.add(point)
            picked.append(i)
    return picked if len(picked) >= 2 else []


def selection_measure(study: Study) -> tuple[str, bool]:
    sel = study.settings.select
    keys = {p.key for p in study.params}
    if sel is not None and sel.measure:
        from cell.experiments.study import selection_goal

        return sel.measure, selection_goal(study) == "maximize"
    o = next((o for o in study.settings.objectives if o.measure not in keys), None)
    if o is None:
        raise ValueError("no objective is a measure; name select.measure")
    return o.measure, o.goal == "maximize"


def label(study: Study, row: Any) -> str:
    return f"trial {int(row['trial'])} (" + ", ".join(
        f"{p.key} {_show(row[p.key])}" for p in study.params) + ")"


def _show(v: Any) -> str:
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def figures(study: Study, o: Any, frame: Any, files: dict[str, Path]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = _objective_columns(study)
    (m0, up0) = cols[0]
    ok = frame["feasible"].astype(bool)
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    ax.scatter(frame["trial"][~ok], frame[m0][~ok], marker="x", color="0.6", label="infeasible")
    ax.scatter(frame["trial"][ok], frame[m0][ok], s=14, color="C0", label="feasible")
    best = frame[m0].where(ok).cummax() if up0 else frame[m0].where(ok).cummin()
    ax.step(frame["trial"], best, where="post", color="C3", label="best feasible so far")
    ax.set_xlabel("trial")
    ax.set_ylabel(m0)
    ax.legend(fontsize=8)
    ax.set_title(f"{study.name}: history")
    fig.tight_layout()
    fig.savefig(files["history.png"], dpi=110, format="png")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(5.6, 4.2))
    x, y = (cols[0][0], cols[1][0]) if len(cols) > 1 else (study.params[0].key, m0)
    ax.scatter(frame[x][~ok], frame[y][~ok], marker="x", color="0.6", label="infeasible")
    ax.scatter(frame[x][ok], frame[y][ok], s=14, color="C0", label="feasible")
    front = frame[frame["on_front"]].sort_values(x)
    ax.plot(front[x], front[y], "o-", color="C3", label="Pareto front" if len(cols) > 1 else "best")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(files["front.png"], dpi=110, format="png")
    plt.close(fig)

    imp = importances(study, o)
    fig, ax = plt.subplots(figsize=(5.6, 0.5 + 0.45 * max(len(imp), 1)))
    names = list(imp)
    ax.barh(names[::-1], [imp[n] for n in names][::-1], color="C0")
    ax.set_xlabel(f"importance for {importance_measure(study)[0]} (PED-ANOVA, Optuna)")
    fig.tight_layout()
    fig.savefig(files["importance.png"], dpi=110, format="png")
    plt.close(fig)


def importances(study: Study, o: Any) -> dict[str, float]:
    """Each key's share of the first objective's variance over the complete trials
    (Optuna's PED-ANOVA, Watanabe et al. 2023: no random forest, so the same trials give the same numbers)."""
    import optuna

    complete = o.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    if len(complete) < 2 or len(study.params) < 1:
        return {}
    try:
        import warnings

        m, up = importance_measure(study)
        ev = optuna.importance.PedAnovaImportanceEvaluator()
        with warnings.catch_warnings():  # its note that it ranks for low targets: ours are signed so
            warnings.simplefilter("ignore", UserWarning)
            return dict(optuna.importance.get_param_importances(
                o, evaluator=ev, target=lambda t: (-1 if up else 1) * t.user_attrs["measures"][m][0]))
    except (RuntimeError, ValueError):  # every trial alike: nothing to attribute
        return {}


def answer(study: Study, front: Any) -> str:
    """The front (or the best) in one sentence."""
    keys = [p.key for p in study.params]
    if not len(front):
        return "No trial met the constraints: widen the ranges or relax the constraints."
    distinct = front.drop_duplicates(subset=keys)
    points = "; ".join(", ".join(f"{k} = {_show(r[k])}" for k in keys) + f" (trial {int(r['trial'])})"
                       for _, r in distinct.sort_values(keys).iterrows())
    cons = " and ".join(str(c) for c in study.constraints) or "no constraint"
    if len(study.settings.objectives) > 1 and len(distinct) == 1:
        return (f"One point is best in every objective at once, so there is no trade-off to choose "
                f"along: {points}, with {cons} kept on the means.")
    if len(study.settings.objectives) > 1:
        return f"The trade-off ({len(distinct)} points, {cons} kept on the means): {points}."
    return f"The best feasible point ({cons} kept on the means): {points}."


#: The share of a key's range at each end that :func:`key_effects` compares.
END_SHARE = 0.25


def key_effects(study: Study, frame: Any) -> list[str]:
    """Each measure's mean over the trials with a numeric key in the lowest quarter of its
    range against those in the highest (every trial that ran, feasible or not), as a table;
    nothing when no numeric key has trials at both ends."""
    ran = frame[frame["refused"] == ""] if len(frame) else frame
    ms = measured(study)
    ends = []
    for p in study.params:
        if p.is_choice or not len(ran):
            continue
        cut = END_SHARE * (p.high - p.low)
        groups = [(lo, hi, ran[(ran[p.key] >= lo) & (ran[p.key] <= hi)])
                  for lo, hi in ((p.low, p.low + cut), (p.high - cut, p.high))]
        if all(len(g) for _, _, g in groups):
            ends += [(p.key, lo, hi, g) for lo, hi, g in groups]
    if not ends:
        return []
    lines = ["## What each key does", "",
             f"Each measure's mean over the trials with a key in the lowest quarter of its range "
             f"and over those in the highest ({len(ran)} trials that ran, feasible or not; the "
             "other keys as the search set them, so an end's trials differ in those too).", "",
             "| measure | " + " | ".join(f"{k} {lo:g}–{hi:g} ({len(g)} trials)"
                                       for k, lo, hi, g in ends) + " |",
             "|---" * (1 + len(ends)) + "|"]
    for m in ms:
        lines.append(f"| {m} | " + " | ".join(f"{float(g[m].mean()):.4g}" for *_, g in ends) + " |")
    return [*lines, ""]


def flatness(study: Study, frame: Any) -> list[str]:
    """With one objective that is a measure and a selection's δ: how many feasible trials are
    within δ of the best on it (the objective is flat over them), as a paragraph."""
    s = study.settings
    keys = {p.key for p in study.params}
    if len(s.objectives) != 1 or s.objectives[0].measure in keys or s.select is None \
            or not len(frame):
        return []
    m, up = s.objectives[0].measure, s.objectives[0].goal == "maximize"
    feasible = frame[frame["feasible"].astype(bool)]
    if not len(feasible):
        return []
    best = float(feasible[m].max() if up else feasible[m].min())
    near = feasible[(feasible[m] - best).abs() <= s.select.delta]
    return ["", f"{len(near)} of the {len(feasible)} feasible trials are within δ = "
            f"{s.select.delta:g} of the best on {m} ({float(near[m].min()):.4g} to "
            f"{float(near[m].max()):.4g}): over them the objective is flat, and what tells "
            "them apart is the other measures (trials.csv, and \"What each key does\")."]


def importance_measure(study: Study) -> tuple[str, bool]:
    """The measure the keys' importance is for: the selection's, else the first objective."""
    try:
        return selection_measure(study)
    except ValueError:
        o = study.settings.objectives[0]
        return o.measure, o.goal == "maximize"


def markdown(study: Study, frame: Any, picked: list[int], sel: Selection | None,
             imp: dict[str, float], command: str) -> str:
    from cell.experiments.selection import sentence, table
    from cell.reporting.formatting import estimate

    s = study.settings
    goals = "; ".join(f"{o.goal} {o.measure}" for o in s.objectives)
    lines = [f"# {study.name}", "", s.description, "",
             f"Regenerate: `{command}`", "",
             f"- Search: {len(frame)} trials by "
             f"{'NSGA-II' if len(s.objectives) > 1 else 'TPE'} (Optuna), seed {s.seed}; {goals}.",
             f"- Each trial: {s.replications} replications of {RunLength.of(study.scenario({}).run)} "
             "over common random numbers (the same streams at every trial), so two trials differ "
             "by their keys, not their draws; each measure's mean has a 95 % t-interval.",
             "- Constraints (on the means): " + (", ".join(str(c) for c in study.constraints) or "none")
             + f"; {int(frame['feasible'].sum()) if len(frame) else 0} of {len(frame)} trials feasible.",
             f"- What that buys: {len(frame) * s.replications:,} runs in the search; a "
             f"constraint's mean is known to the ± beside it (a trial near a bound may be on "
             "either side of it: KN's re-runs and more replications settle that), and the search "
             "resolves a key to its step, not finer.",
             "", "## Varied keys", "", "| key | range |", "|---|---|"]
    for p in study.params:
        rng = ", ".join(map(str, p.choices)) if p.is_choice else \
            f"[{p.low:g}, {p.high:g}]" + (" log" if p.log else "") + (f" step {p.step:g}" if p.step else "")
        lines.append(f"| {p.key} | {rng} |")
    front = frame[frame["on_front"]] if len(frame) else frame
    title = "Pareto front" if len(s.objectives) > 1 else "Best feasible trial"
    lines += ["", "## Answer", "", answer(study, front), *flatness(study, frame), "", f"## {title}", ""]
    if not len(front):
        lines.append("No trial met the constraints.")
    else:
        ms = measured(study)
        keys = [p.key for p in study.params]
        lines += ["| trial | " + " | ".join(keys + ms) + " |", "|---" * (1 + len(keys) + len(ms)) + "|"]
        shown = front.drop_duplicates(subset=keys)  # a point the search tried twice: once
        for _, r in shown.sort_values([study.settings.objectives[0].measure, "trial"]).iterrows():
            cells = [_show(r[k]) for k in keys] + [estimate(r[m], r[m + '_ci95']) for m in ms]
            lines.append(f"| {int(r['trial'])} | " + " | ".join(cells) + " |")
    lines += ["", "![history](history.png) ![front](front.png)", ""]
    lines += key_effects(study, frame)
    lines += ["## Importance", ""]
    lines += [f"- {k}: {v:.2f}" for k, v in imp.items()] or ["- (too few trials)"]
    lines += ["", "![importance](importance.png)", ""]
    if sel is not None:
        m, _ = selection_measure(study)
        labels = [label(study, frame.loc[i]) for i in picked]
        lines += ["## Selection of the best", "",
                  f"The {len(picked)} best feasible trials re-run on fresh streams (replications "
                  f"from {SELECT_OFFSET:,} on, not those of the search, so the search's luck does "
                  f"not carry over), first stage n0 = {s.select.n0 if s.select else ''}, at most "
                  f"{s.select.max if s.select else ''} each.", "",
                  sentence(sel, labels, m), "", *table(sel, labels, m), ""]
    return "\n".join(lines)
