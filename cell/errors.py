"""One exception tree, rooted at :class:`CellError`.

The command line turns any ``CellError`` into one line on stderr and exit code 2.
"""

from __future__ import annotations


class CellError(Exception):
    """Base of every error the package raises on purpose."""


class ScenarioError(CellError, ValueError):
    """A scenario (or sweep) file has a bad key or value.

    The message always names the file, the dotted key and the offending value.
    """

    def __init__(self, file: object, key: str, value: object, why: str):
        self.file, self.key, self.value, self.why = str(file), key, value, why
        super().__init__(f"{self.file}: {key} = {value!r}: {why}")


class UnreachableError(CellError, ValueError):
    """A pose is out of the arm's reach or outside a joint's range.

    ``index`` is the position of the first bad pose in the batch given to the
    inverse kinematics; ``joint`` the joint (0-4) outside its range, or None when
    the pose is out of reach altogether.
    """

    def __init__(self, message: str, index: int = 0, joint: int | None = None):
        self.index, self.joint = index, joint
        super().__init__(message)


class InfeasibleError(CellError, ValueError):
    """A requested timing asks more than the motors can give."""


class NoMotionError(CellError):
    """No admissible motion along a path under the given bounds (the planner)."""
