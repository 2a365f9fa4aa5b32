"""The thesis's figures, regenerated from this model: ``cell figures``.

Writes ``figNN_<slug>.png`` for Fig. 8, 9, 12-30 of the thesis's list of
illustrations, each titled with its number and caption (Fig. 13/14 of arrivals other
than a Weibull named after them: :func:`file_stem`).  Fig. 8-21 need only the
path and the motors; Fig. 22-30 run the simulation (adaptive, and non-adaptive at
the scenario's own cycle for Fig. 23/24 and at the six robot cycles of Table 7.1
for Fig. 25-30: those the robot cannot make are left out).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

from cell.arm.steptable import StepTable
from cell.reporting.figures import interarrival as arrivals
from cell.reporting.figures import layout, motion, runs, tip
from cell.reporting.figures.style import style
from cell.scenario.schema import Scenario
from cell.sim.physics_checks import step_table

#: Figure number -> file stem, as written into the output folder.
FILES: dict[int, str] = {
    8: "fig08_working_environment",
    9: "fig09_path_definition",
    12: "fig12_hand_length",
    13: "fig13_weibull_pdf",
    14: "fig14_weibull_cdf",
    15: "fig15_coordinates_vs_time",
    16: "fig16_joint_angles_vs_time",
    17: "fig17_theta1_rates",
    18: "fig18_theta2_rates",
    19: "fig19_theta3_rates",
    20: "fig20_theta4_rates",
    21: "fig21_theta5_rates",
    22: "fig22_tip_velocity",
    23: "fig23_delivery_interval_lumped",
    24: "fig24_delivery_interval_running",
    25: "fig25_ip_22_5872",
    26: "fig26_ip_22_0000",
    27: "fig27_ip_21_5000",
    28: "fig28_ip_21_0000",
    29: "fig29_ip_20_5000",
    30: "fig30_ip_20_0907",
}
#: Every file a figure set may hold: Fig. 13/14 are named after the arrivals (:func:`file_stem`).
NAMES: tuple[str, ...] = (*(f"{stem}.png" for n, stem in FILES.items() if n not in (13, 14)),
                          "fig13_*_pdf.png", "fig14_*_cdf.png")


def file_stem(number: int, scenario: Scenario) -> str:
    """Figure ``number``'s file stem: :data:`FILES`'s, but Fig. 13/14 of arrivals that are not
    the thesis's Weibull are named after their family (``fig13_gamma_pdf``) or the trace's."""
    given = scenario.arrivals
    if number not in (13, 14) or (given.trace_csv is None and given.distribution == "weibull_min"):
        return FILES[number]
    family = "trace" if given.trace_csv is not None else \
        arrivals.FAMILY_NAMES.get(given.distribution, given.distribution).lower()
    return f"fig{number}_{family}_{'pdf' if number == 13 else 'cdf'}"


def _draw_path_figures(scenario: Scenario, table: StepTable, wanted: set[int],
                       path: dict[int, Path], done: Callable[[Path], None]) -> None:
    """Fig. 8, 9 and 12 (the cell and the path), 13/14 (the arrivals)."""
    if 8 in wanted:
        done(layout.fig08_working_environment(scenario, table, path[8]))
    if 9 in wanted:
        done(layout.fig09_path(scenario, table, path[9]))
    if 12 in wanted:
        done(layout.fig12_hand_length(scenario, path[12]))
    if wanted & {13, 14}:
        x = arrivals.draws(scenario, scenario.run.parts)
        if 13 in wanted:
            done(arrivals.fig13_pdf(scenario, x, path[13]))
        if 14 in wanted:
            done(arrivals.fig14_cdf(scenario, x, path[14]))


def _draw_motion_figures(scenario: Scenario, table: StepTable, wanted: set[int],
                         path: dict[int, Path], done: Callable[[Path], None]) -> None:
    """Fig. 15-21: the arm's motion along the path."""
    # drawn on the joints' travel; Fig. 17-21's whole steps on the simulation's own timing
    tl = motion.nominal_timeline(table, scenario, motion.joint_travel_min_times(table))
    steps_tl = motion.nominal_timeline(table, scenario)
    if 15 in wanted:
        done(motion.fig15_coordinates(table, tl, path[15]))
    if 16 in wanted:
        done(motion.fig16_joint_angles(table, tl, path[16]))
    for joint in range(5):
        if 17 + joint in wanted:
            done(motion.fig_joint_rate(table, tl, steps_tl, scenario, joint,
                                        path[17 + joint]))


def _draw_run_figures(scenario: Scenario, table: StepTable, wanted: set[int],
                      path: dict[int, Path], done: Callable[[Path], None]) -> None:
    """Fig. 22-30, from simulated runs (only those the wanted figures need)."""
    if wanted & set(range(22, 31)):
        sims = runs.simulate_runs(scenario, tuple(
            c for n, c in runs.IP_FIGURES.items() if n in wanted))
        if 22 in wanted:
            done(tip.fig22_tip_velocity(sims, table, scenario, path[22]))
        if 23 in wanted:
            done(runs.fig23_lumped(sims, scenario, path[23]))
        if 24 in wanted:
            done(runs.fig24_running(sims, scenario, path[24]))
        for number, cycle in runs.IP_FIGURES.items():
            if number in wanted:
                done(runs.fig_ip(sims, cycle, number, path[number]))


def make_figures(scenario: Scenario, out: str | Path, *, parts: int | None = None,
                 only: Iterable[int] | None = None,
                 progress: Callable[[Path], None] | None = None,
                 warn: Callable[[str], None] | None = None) -> list[Path]:
    """Draw the figures of ``scenario`` into ``out``; return the files written.

    ``parts`` overrides ``run.parts`` (fewer parts draw faster); ``only`` limits
    the figure numbers drawn.  Fig. 25-30 whose Table 7.1 cycle the non-adaptive
    robot cannot make are left out, and ``warn`` is told so in one line first.
    """
    out = Path(out)
    if parts is not None:
        scenario = scenario.with_overrides({"run.parts": parts})
    wanted = set(FILES) if only is None else set(only)
    path = {n: out / f"{file_stem(n, scenario)}.png" for n in FILES}
    written: list[Path] = []

    def done(p: Path) -> None:
        written.append(p)
        if progress:
            progress(p)

    skipped, note = runs.skipped_note(scenario, wanted)
    if note and warn:
        warn(note)  # before anything is drawn
    wanted -= set(skipped)
    with style():
        table = step_table(scenario)
        _draw_path_figures(scenario, table, wanted, path, done)
        _draw_motion_figures(scenario, table, wanted, path, done)
        _draw_run_figures(scenario, table, wanted, path, done)
    return written
