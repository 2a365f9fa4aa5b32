"""Type aliases shared by the numeric modules."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: An array of floats (positions, rates, path parameters...).
Array = NDArray[np.float64]
#: One value for each of the robot's five joints.
Five = tuple[float, float, float, float, float]
