"""``cell animate``: watch the cell run, seen from above (thesis §4.1, Fig. 8).

The arm, both belts and every part at its true position, frame by frame, with
the clock, the counts of parts arrived, delivered and lost, the belt speeds and
the robot's regime; ``--policy both`` puts the adaptive robot (§5.3) beside the
fixed-cycle one (§6.3) on the same parts (same seed: common random numbers).

:mod:`cell.reporting.animation.scene` says where everything is at an instant (pure
numpy); :mod:`cell.reporting.animation.render` draws it.  This module only wires them to
the command line; it imports neither numpy nor matplotlib, so ``cell --help``
stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cell.plumbing.errors import CellError

if TYPE_CHECKING:
    from cell.reporting.animation.scene import Scene
    from cell.scenario.schema import Scenario

SUFFIXES = (".gif", ".mp4")
POLICIES = ("adaptive", "non-adaptive", "both")
#: Parts simulated past the last one shown, to start with (doubled until enough).
EXTRA_PARTS = 3
#: A GIF's frames are all held (one byte a pixel) until it is written: at most this much.
GIF_MEMORY_BYTES = 1.5e9
#: The fields of a part's record that the frames need (:func:`~cell.reporting.animation.scene.frames_input`).
FRAME_FIELDS = ("part", "arrival_s", "at_bot_s", "picked", "pick_s", "touchdown_s",
                "r1_s", "r2_s", "r3_s", "r4_s")
#: The fields a run with a ``buffer:`` adds (its parts' waits at the gate, docs/layout.md).
BUFFER_FIELDS = ("buffer_wait_s",)
#: Runs of at least this many parts show their progress on stderr while they are simulated.
PROGRESS_FROM_PARTS = 50_000


@dataclass(frozen=True)
class Rendered:
    """What :func:`animate` wrote."""

    path: Path
    frames: int
    t0_s: float
    """Simulated time of the first frame."""
    t1_s: float
    """Simulated time of the last frame."""
    size_bytes: int


def check_output(out: str | Path) -> Path:
    """The output path if it can be written: .gif, or .mp4 with ffmpeg on the PATH."""
    path = Path(out)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise CellError(f"--out {str(out)!r}: the animation is written as .gif or .mp4, "
                        f"not {suffix or 'a file without a suffix'!r}")
    if suffix == ".mp4" and not has_ffmpeg():
        raise CellError("MP4 needs ffmpeg on the PATH; write a .gif instead")
    return path


def has_ffmpeg() -> bool:
    """Whether ffmpeg is on the PATH (what an MP4 needs)."""
    from matplotlib.animation import writers

    return bool(writers.is_available("ffmpeg"))


def simulated(scenario: Scenario, progress: bool = False) -> Any:
    """The run, keeping of each part only :data:`FRAME_FIELDS` (as a flat array each: a
    deep ``--from-part`` runs millions of parts); ``.parts``, ``.belts`` and ``.summary``
    as :func:`~cell.sim.simulation.simulate`'s result has them."""
    from array import array
    from operator import attrgetter
    from types import SimpleNamespace

    import numpy as np
    import pandas as pd

    from cell.plumbing.progress import Progress
    from cell.sim.simulation import simulate

    kept = FRAME_FIELDS + (BUFFER_FIELDS if scenario.buffer is not None else ())
    columns = {f: array("d") for f in kept}
    appends, fields = [columns[f].append for f in kept], attrgetter(*kept)
    n = scenario.run.parts
    with Progress(n, f"cell animate: simulating ({scenario.controller.policy})", "parts",
                  enabled=progress and n >= PROGRESS_FROM_PARTS) as bar:
        step = max(1, n // 200)

        def keep(record: Any) -> None:
            for add, value in zip(appends, fields(record)):
                add(value)
            if bar.enabled and record.part % step == 0:
                bar.update(step)

        result = simulate(scenario, keep_parts=False, on_part=keep,
                          keep_stations=bool(scenario.stations))
        bar.update(n - bar.n)
    parts = pd.DataFrame({f: np.frombuffer(columns[f]) for f in kept})
    parts = parts.astype({"part": np.int64, "picked": bool})
    return SimpleNamespace(parts=parts, belts=result.belt_histories(), summary=result.summary,
                           stops=run_stops(result), stations=station_inputs(result))


def station_inputs(result: Any) -> list[Any]:
    """The frames' input of each station of a line of ``stations:``, the first's first (none
    without one): each from its own log, a part's wait at each station the growth of its
    ``buffer_wait_s`` since the station before."""
    import numpy as np

    from cell.reporting.animation.scene import station_input

    line = result.line
    if line is None or len(line.cells) == 1:
        return []
    so_far: dict[int, float] = {}  # each part's buffer_wait_s after the stations before
    out = []
    for i, ((name, placement, own), log, belts) in enumerate(zip(line.cells, line.logs,
                                                                  line.belt_logs)):
        visits = log.visit_table()
        parts = visits["part"].astype(np.int64)
        before = np.array([so_far.get(int(p), 0.0) for p in parts])
        so_far.update(zip(parts.tolist(), visits["waited"].tolist()))
        out.append(station_input(f"{name}, {placement}" if i else "", own, visits,
                                 result.belt_histories() if belts is None else
                                 type(result)(None, None, belts).belt_histories(),
                                 visits["waited"] - before))
    return out


def run_stops(result: Any) -> tuple[tuple[str, str, float, float], ...]:
    """(equipment, cause, from_s, to_s) of every stop of a run: its failures and planned
    stops (``failures:``), and the robot's stops for a worn motor (``wear:``)."""
    if getattr(result, "downtime", None) is not None:  # the first station's failures.csv rows
        rows = [(e, cause, a, b) for e, cause, a, b, _ in result.stop_rows]
    else:
        wear = getattr(result, "wear", None)
        rows = [("robot", "wear", a, b) for a, b, _ in (wear.stops if wear else [])]
    return tuple(sorted(rows, key=lambda r: (r[2], r[0])))


def simulate_scenes(scenario: Scenario, policies: list[str], first: int, count: int,
                    progress: bool = False) -> list[Scene]:
    """Each policy's run, long enough that every part on the belts in the window exists.

    Parts are numbered as in a run of any length (the feeder's draws are the same
    whatever ``run.parts`` is), and the parts after the window keep the last one
    shown from being the run's last (whose look-ahead would find nothing coming).
    Each scene times the robot's cycles from part ``first``'s earliest arrival in any
    run on: a part the feeder holds back arrives at different instants under the two
    policies, and the window starts at its arrival in the first run.
    """
    from cell.reporting.animation.scene import build_scene, frames_input, window
    from cell.sim.physics_checks import step_table

    if count < 1 or first < 1:
        raise CellError(f"--parts {count} --from-part {first}: both must be at least 1")
    table = step_table(scenario)
    extra = EXTRA_PARTS
    while True:
        n = first + count - 1 + extra
        runs = []
        for policy in policies:
            # the adaptive robot runs at the nominal cycle: a fixed robot's own cycle
            # (controller.ideal_cycle_s) is the non-adaptive panel's alone, as in cell figures
            own = {"controller.ideal_cycle_s": None} if policy == "adaptive" else {}
            s = scenario.with_overrides({"controller.policy": policy, "run.parts": n,
                                         "run.hours": None, **own})  # a run of parts, hours or not
            run = simulated(s, progress)
            line = run.stations  # a line's stations, the first's first (one policy: its run's)
            runs.append((line[0] if line else frames_input(run, s), s, run.stops))
        from_s = min(float(data.arrival_s[first - 1]) for data, _, _ in runs)
        scenes = [build_scene(data, table, s, from_s=from_s, stops=stops)
                  for data, s, stops in runs]
        scenes += [build_scene(data, step_table(own.scenario), own.scenario, from_s=from_s)
                   for data, own in station_cells(s, line[1:])]
        _, t1 = window(scenes, first, count)
        if all(sc.data.arrival_s[-1] > t1 for sc in scenes if not sc.data.station):
            return scenes
        extra *= 2


def station_cells(scenario: Scenario, line: list[Any]) -> list[Any]:
    """(frames' input, assembled cell) of each station after the first of ``scenario``."""
    if not line:
        return []
    from cell.sim.assembly import assemble

    return list(zip(line, [own for _, own in assemble(scenario).line]))


def animate(scenario: Scenario, out: str | Path, *, policy: str | None = None, parts: int = 12,
            first: int = 1, speed: float = 20.0, fps: int = 12, dpi: float = 100.0,
            progress: bool = True) -> Rendered:
    """Simulate, then draw parts ``first`` .. ``first + parts - 1`` into ``out``, whole or not at all.

    ``policy``: 'adaptive', 'non-adaptive', 'both' or None (the scenario's).  A frame
    every ``speed / fps`` simulated seconds.
    """
    from cell.plumbing.output.atomic import atomic_path
    from cell.reporting.animation.render import render
    from cell.reporting.animation.scene import frame_times, window

    path = check_output(out)
    if not (speed > 0 and fps > 0 and dpi > 0):
        raise CellError(f"--speed {speed:g} --fps {fps:g} --dpi {dpi:g}: all must be positive")
    chosen = policy or scenario.controller.policy
    if chosen not in POLICIES:
        raise CellError(f"--policy {chosen!r}: one of {', '.join(POLICIES)}")
    policies = ["adaptive", "non-adaptive"] if chosen == "both" else [chosen]
    if scenario.stations and len(policies) > 1:
        raise CellError("--policy both: a line of stations is drawn under one policy, its "
                        "own stations' beside it")
    scenes = simulate_scenes(scenario, policies, first, parts, progress)
    t0, t1 = window(scenes, first, parts)
    times = frame_times(t0, t1, speed / fps)
    if path.suffix.lower() == ".gif":
        from cell.reporting.animation.render import frame_pixels

        need = len(times) * frame_pixels(len(scenes), dpi)
        if need > GIF_MEMORY_BYTES:
            raise CellError(f"{len(times)} frames would hold {need / 1e9:.1f} GB while the GIF "
                            f"is built; raise --speed, lower --dpi or --parts"
                            + (", or write a .mp4" if has_ffmpeg() else ""))
    with atomic_path(path) as tmp:  # written in place: a killed run's .tmp is swept later
        render(scenes, times, tmp, fps=fps, dpi=dpi, progress=progress, target=path)
    return Rendered(path, len(times), float(times[0]), float(times[-1]), path.stat().st_size)


def animate_both(scenario: Scenario, out: str | Path, **options: Any) -> Rendered:
    """The adaptive and the fixed-cycle robot side by side, same parts, same clock."""
    return animate(scenario, out, policy="both", **options)


#: The demo's window on the baseline scenario (seed 1984): parts 3-12, of which the
#: fixed-cycle robot loses four (3, 7, 9, 11) and the adaptive one none.
DEMO_FIRST, DEMO_PARTS, DEMO_SPEED = 3, 10, 10.0


def demo(out_path: str | Path, *, progress: bool = True) -> Rendered:
    """The committed demo: both robots side by side on ``scenarios/baseline.yaml``,
    parts 3-12, ten simulated seconds a second."""
    from cell.scenario.schema import load_scenario

    return animate_both(load_scenario("baseline"), out_path, parts=DEMO_PARTS, first=DEMO_FIRST,
                        speed=DEMO_SPEED, progress=progress)
