"""The GIF and MP4 writers: each writes its format to any file name (the caller's
temporary ``.tmp`` file, which a later run sweeps away if this one is killed), and
each can be abandoned, when the drawing stops half-way, without finishing the file.
"""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from typing import Any

import numpy as np
from matplotlib.animation import FFMpegWriter, PillowWriter
from matplotlib.figure import Figure

from cell.plumbing.errors import CellError


class CanvasGifWriter(PillowWriter):
    """matplotlib's Pillow GIF writer, taking each frame as last drawn on the Agg canvas
    and keeping it at one byte a pixel.

    PillowWriter redraws the whole figure for every frame and holds each as RGB(A)
    to the end: a few hundred 1100 x 700 frames would take most of a gigabyte.
    Here the caller draws (only what moved), each frame is reduced to its own
    palette at once (a frame of this drawing has some 250 colours), and each is
    let go as Pillow takes its copy.
    """

    def setup(self, fig: Figure, outfile: Any, dpi: float | None = None) -> None:
        super().setup(fig, outfile, dpi=dpi)
        self._paletted: list[Any] = []

    def grab_frame(self, **savefig_kwargs: Any) -> None:
        from PIL import Image

        rgba = np.asarray(self.fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
        self._paletted.append(Image.fromarray(rgba[..., :3]).quantize(
            256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE))

    def abandon(self) -> None:
        """Let the frames go: :meth:`finish` then writes nothing."""
        self._paletted.clear()

    def finish(self) -> None:
        frames = self._paletted
        if not frames:
            return
        # GIF delays are whole hundredths of a second: alternate them to keep the mean rate
        ticks = np.round(np.arange(len(frames) + 1) * 100 / self.fps)
        duration = [int(10 * d) for d in np.diff(ticks)]
        frames.reverse()

        def handed_over() -> Iterator[Any]:   # Pillow copies each frame: let go of ours
            while frames:
                yield frames.pop()

        first = frames.pop()
        first.save(self.outfile, format="GIF", save_all=True, append_images=handed_over(),
                   duration=duration, loop=0)


class Mp4Writer(FFMpegWriter):
    """matplotlib's ffmpeg writer, H.264 in an MP4 container whatever the file's name.

    ffmpeg's failing is one line (:class:`CellError`) rather than matplotlib's
    CalledProcessError; an abandoned writer stops ffmpeg rather than waiting on it.
    """

    def __init__(self, fps: int, name: str):
        super().__init__(fps=fps, codec="h264", extra_args=["-f", "mp4"])
        self.name = name
        """The file being written, as its errors name it."""
        self._abandoned = False

    def abandon(self) -> None:
        """Stop ffmpeg (Ctrl-C may have stopped it already): :meth:`finish` then does nothing."""
        self._abandoned = True
        proc = getattr(self, "_proc", None)
        if proc is not None:
            proc.kill()
            proc.communicate()

    def finish(self) -> None:
        if self._abandoned:
            return
        try:
            super().finish()
        except subprocess.CalledProcessError as exc:
            said = [line for line in (exc.stderr or "").splitlines() if line.strip()]
            raise CellError(f"{self.name}: ffmpeg stopped with exit status {exc.returncode}"
                            + (f": {said[-1].strip()}" if said else "")) from None
