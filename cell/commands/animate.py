"""``cell animate SCENARIO [--parts N] [--from-part K] --out FILE.gif|.mp4``: watch the cell.

The cell from above (thesis Fig. 8): both belts with every part where the belts'
speed history puts it, the arm's links from its joint angles along the path,
the clock, the counts and the belt speeds (:mod:`cell.animation`).
"""

from __future__ import annotations

import argparse

from cell.commands import scenario_arguments

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


def main(args: argparse.Namespace) -> int:
    from cell.animation import animate, check_output

    check_output(args.out)  # before anything is simulated
    from cell.overrides import parse_sets
    from cell.scenario import load_scenario

    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    done = animate(scenario, args.out, policy=args.policy, parts=args.parts, first=args.from_part,
                   speed=args.speed, fps=args.fps, dpi=args.dpi)
    print(f"wrote {done.path}: {done.frames} frames, simulated {done.t0_s:.1f}-{done.t1_s:.1f} s, "
          f"{done.size_bytes / 1e6:.2f} MB")
    return 0
