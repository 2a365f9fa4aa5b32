"""``python -m cell.reporting.animation [OUT]``: write the committed demo (``make animation``).

Both robots side by side on the baseline scenario (:func:`cell.reporting.animation.movie.demo`),
by default into ``reports/animation/both.gif``.
"""

from __future__ import annotations

import sys

from cell.reporting.animation.movie import demo

OUT = "reports/animation/both.gif"


def main(argv: list[str]) -> int:
    out = argv[0] if argv else OUT
    done = demo(out)
    print(f"wrote {done.path}: {done.frames} frames, simulated {done.t0_s:.1f}-{done.t1_s:.1f} s, "
          f"{done.size_bytes / 1e6:.2f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
