"""A writable home for matplotlib's configuration and cache when the one it would use cannot be
written (:func:`matplotlib_home`, made by ``cell``'s command at its start, removed at its end)."""

from __future__ import annotations

import contextlib
import os


def usable(path: str) -> bool:
    """Whether ``path`` is, or could be made as, a folder one can write in (nothing made)."""
    path = os.path.abspath(path)
    while not os.path.lexists(path):
        parent = os.path.dirname(path)
        if parent == path:
            return False
        path = parent
    return os.path.isdir(path) and os.access(path, os.W_OK | os.X_OK)


def matplotlib_home(made: list[str]) -> None:
    """A temporary folder for matplotlib's configuration and cache, made (and put in
    ``MPLCONFIGDIR``) only when the one it would use cannot be written (a read-only or
    file-valued ``HOME``, a bad ``MPLCONFIGDIR``): matplotlib would otherwise warn on stderr
    and leave its own temporary folder behind.  Its name goes into ``made`` before the folder
    is made, so that the caller removes it at the end even if a stop cut this short."""
    given = os.environ.get("MPLCONFIGDIR")
    if given:
        wanted = given
    else:
        base = os.environ.get("XDG_CONFIG_HOME", "")
        if not os.path.isabs(base):
            base = os.path.join(os.path.expanduser("~"), ".config")
        wanted = os.path.join(base, "matplotlib")
    from cell.plumbing.output.paths import umask_blocks

    blocked = umask_blocks()  # what matplotlib would make, it could not write in
    if os.path.isabs(wanted) and usable(wanted) and not (blocked and not os.path.isdir(wanted)):
        return
    import tempfile

    try:
        parent = tempfile.gettempdir()
    except OSError:  # no temporary folder can be written: matplotlib's own warning stands
        return
    for _ in range(100):
        made[:] = [os.path.join(parent, f"cell-matplotlib-{os.urandom(6).hex()}")]
        try:
            os.mkdir(made[0], 0o700)
        except FileExistsError:  # (not ours: never to be removed)
            made.clear()
            continue
        except OSError:
            break
        try:
            os.chmod(made[0], 0o700)  # the owner's, whatever the umask took
        except OSError:
            with contextlib.suppress(OSError):
                os.rmdir(made[0])
            break
        os.environ["MPLCONFIGDIR"] = made[0]
        return
    made.clear()
