"""cell: a simulation of King's (1984) robotic transfer station.

A five-axis MICROBOT arm takes parts off an input conveyor and sets them down,
evenly spaced, on an output conveyor while parts arrive at random.  The maths
(kinematics, path, motors, controller decisions) are pure functions; the SimPy
processes are thin shells around them.
"""

# First of all: Ctrl-C and kill said as ``cell`` says them, if this process is the command.
from cell.plumbing import startup as _startup  # noqa: F401  (installs on import)
from cell.plumbing.errors import CellError, ScenarioError, UnreachableError

__all__ = ["CellError", "ScenarioError", "UnreachableError", "__version__"]
__version__ = "0.1.0"
