"""Several ``cell`` commands in one real process, each with its standard output (or error) on a
pipe whose reader has already left, or on a full device (``/dev/full``): what
tests/plumbing/test_output_streams.py runs, one interpreter start-up for them all.

``python closed_reader.py SPEC RESULTS``: SPEC, a JSON list of ``{"args": [...], "closed":
"stdout" | "stderr", "device": "pipe" | "full"}``; RESULTS, where the JSON list of outcomes goes:
the exit code main() gave (or the exception that escaped it), what the other stream received,
and the error of the flush the interpreter makes as it exits (None if none: with one, the process
would have ended with exit code 120).  Each command gets new descriptors 1 and 2, so what one
command's guard did to them (the null device put there) does not reach the next.
"""

from __future__ import annotations

import gc
import json
import os
import sys
import tempfile
import traceback


def _target(device: str) -> int:
    if device == "full":
        return os.open("/dev/full", os.O_WRONLY)
    read, write = os.pipe()
    os.close(read)  # every write to the pipe now fails with EPIPE
    return write


def _final_flush() -> str | None:
    """The flush the interpreter makes as it exits (its failure: exit code 120)."""
    failed = None
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError) as exc:
            failed = failed or repr(exc)
            devnull = os.open(os.devnull, os.O_WRONLY)  # what the buffer holds goes nowhere
            os.dup2(devnull, stream.fileno())
            os.close(devnull)
            stream.flush()
    return failed


def run_one(args: list[str], closed: str, device: str) -> dict[str, object]:
    from cell.cli.main import main

    closed_fd, other_fd = (1, 2) if closed == "stdout" else (2, 1)
    with tempfile.TemporaryFile() as other:
        target = _target(device)
        os.dup2(target, closed_fd)
        os.close(target)
        os.dup2(other.fileno(), other_fd)
        code: int | None = None
        escaped = None
        try:
            code = main(args)
        except SystemExit as exc:
            escaped = f"SystemExit({exc.code!r})"
        except BaseException:
            escaped = traceback.format_exc()
        gc.collect()  # destructors run now, as they would as the process ends
        flush = _final_flush()
        other.seek(0)
        said = other.read().decode(errors="replace")
    return {"args": args, "code": code, "escaped": escaped, "other": said, "flush": flush}


def main() -> int:
    spec, results = sys.argv[1:3]
    with open(spec) as f:
        commands = json.load(f)
    saved = os.dup(1), os.dup(2)
    outcomes = []
    for command in commands:
        outcomes.append(run_one(command["args"], command["closed"], command.get("device", "pipe")))
    for fd, copy in zip((1, 2), saved):
        os.dup2(copy, fd)
    with open(results, "w") as f:
        json.dump(outcomes, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
