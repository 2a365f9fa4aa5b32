"""``cell animate SCENARIO [--parts N] [--from-part K] --out FILE.gif|.mp4``: watch the cell.

The cell from above (thesis Fig. 8), a buffer's waiting parts at its gate, and each station
of a line in a column beside it: both belts with every part where the belts' speed history
puts it, the arm's links from its joint angles along the path, the clock, the counts and the
belt speeds (:mod:`cell.reporting.animation.movie`).
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from cell.cli.common import scenario_arguments, scenario_of

if TYPE_CHECKING:
    from cell.scenario.schema import Scenario

HELP = "watch the cell run: a GIF or MP4 of the cell from above"
DESCRIPTION = ("Animate a run seen from above: belts, parts at their true positions, the arm, "
               "the clock, counts and belt speeds; --policy both shows the two robots side by side.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    scenario_arguments(parser)
    parser.add_argument("--parts", type=int, default=12, metavar="N",
                        help="how many parts to follow (default 12)")
    parser.add_argument("--from-part", dest="from_part", type=int, default=1, metavar="K",
                        help="the first part to follow (default 1): the animation runs from its "
                             "arrival to part K+N-1's set-down or fall")
    parser.add_argument("--policy", choices=("adaptive", "non-adaptive", "both"), default=None,
                        help="controller to show (default: the scenario's); 'both' puts the "
                             "adaptive and the fixed-cycle robot side by side on the same parts")
    parser.add_argument("--out", required=True, metavar="FILE",
                        help="FILE.gif (Pillow) or FILE.mp4 (needs ffmpeg on the PATH)")
    parser.add_argument("--speed", type=float, default=20.0,
                        help="simulated seconds per second of animation (default 20)")
    parser.add_argument("--fps", type=int, default=12, help="frames per second (default 12)")
    parser.add_argument("--dpi", type=float, default=100.0, help="resolution (default 100)")


#: Bounds on the options: each beyond them is refused before anything is simulated.
LIMITS = {"parts": (1, 10_000), "from_part": (1, 10_000_000), "speed": (0.01, 1e4),
          "fps": (1, 120), "dpi": (10, 1000)}
#: The most frames an animation may have (a part every nominal cycle or mean inter-arrival time).
MAX_FRAMES = 100_000


#: The largest frame drawn (pixels): about 5 s a frame on a slow machine (a quarter of a second
#: a megapixel, measured), so a long animation is not minutes a frame.
MAX_FRAME_PIXELS = 20_000_000


def check_frame_size(dpi: float, columns: int) -> None:
    """Refuse a ``--dpi`` whose frames would be too large to draw in reasonable time."""
    from cell.plumbing.errors import CellError
    from cell.reporting.animation.render import frame_pixels

    pixels = frame_pixels(columns, dpi)
    if pixels > MAX_FRAME_PIXELS:
        most = dpi * (MAX_FRAME_PIXELS / pixels) ** 0.5
        raise CellError(f"--dpi {dpi:g}: frames of {pixels / 1e6:.0f} megapixels, more than "
                        f"{MAX_FRAME_PIXELS / 1e6:.0f} (each would take many seconds to draw); "
                        f"use --dpi {int(most)} or less")


def check_options(args: argparse.Namespace, cycle_s: float, stations: int = 0) -> None:
    """Every option within its bounds, and a frame count that can be drawn, or one line
    (``stations``: a line's stations after the first, each a column beside the first's)."""
    import math

    from cell.plumbing.errors import CellError

    columns = 2 if args.policy == "both" else 1 + stations
    for key, (lo, hi) in LIMITS.items():
        value = getattr(args, key)
        if not (math.isfinite(value) and lo <= value <= hi):
            option = "--" + key.replace("_", "-")
            raise CellError(f"{option} {value:g}: must be between {lo:g} and {hi:g}")
    check_frame_size(args.dpi, columns)
    frames = (args.parts + 1) * cycle_s / args.speed * args.fps
    if frames > MAX_FRAMES:
        raise CellError(f"--parts {args.parts} --speed {args.speed:g} --fps {args.fps}: about "
                        f"{frames:,.0f} frames, more than {MAX_FRAMES:,}; raise --speed or "
                        "lower --parts or --fps")


def notes(scenario: Scenario, first: int, parts: int) -> list[str]:
    """``cell run``'s warnings (:func:`~cell.reporting.unit_slips.run_warnings`), and a note if the
    parts shown go past the scenario's ``run.parts`` (the run is simulated on to reach them)."""
    from cell.reporting.unit_slips import run_warnings
    from cell.scenario.run_length import expected_parts
    from cell.sim.assembly import assemble

    out = [f"warning: {line}" for line in run_warnings(assemble(scenario))]
    last, n, hours = first + parts - 1, round(expected_parts(scenario)), scenario.run.hours
    if last > n:
        end = f"run.parts = {n:,}" if hours is None else f"the about {n:,} that come in run.hours = {hours:g}"
        out.append(f"note: --from-part {first} --parts {parts} shows parts up to {last:,}, past "
                   f"{end}: the run is simulated on past its end to show them")
    return out


def main(args: argparse.Namespace) -> int:
    from cell.plumbing.output.atomic import check_file
    from cell.reporting.animation.movie import animate, check_output

    check_output(args.out)  # before anything is simulated
    check_file(args.out)
    scenario = scenario_of(args)
    from cell.scenario.arrivals import mean_interarrival

    check_options(args, max(scenario.controller.nominal_cycle_s or 0.0,
                            mean_interarrival(scenario.arrivals, scenario.base_dir)),
                  len(scenario.stations or ()))
    for line in notes(scenario, args.from_part, args.parts):
        print(f"cell: {line}", file=sys.stderr)
    done = animate(scenario, args.out, policy=args.policy, parts=args.parts, first=args.from_part,
                   speed=args.speed, fps=args.fps, dpi=args.dpi)
    print(f"wrote {done.path}: {done.frames} frames, simulated {done.t0_s:.1f}-{done.t1_s:.1f} s, "
          f"{done.size_bytes / 1e6:.2f} MB")
    return 0
