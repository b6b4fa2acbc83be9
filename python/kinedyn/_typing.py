"""Type aliases used in the public API's annotations (``kinedyn._typing``; for type checkers and
readers: nothing here is needed at run time)."""

from __future__ import annotations

import os
from typing import Union

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["ArrayLike", "FloatOrArray", "PathLike", "SeedLike"]

#: a file name or path
PathLike = Union[str, "os.PathLike[str]"]
#: what :func:`numpy.random.default_rng` accepts: None (fresh entropy), a seed, or a generator
SeedLike = Union[None, int, np.random.SeedSequence, np.random.BitGenerator, np.random.Generator]
#: one value for one state, an array of values for a batch of states
FloatOrArray = Union[float, np.ndarray]
