"""``kinedyn.symbolic.lagrange``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.lagrange`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import lagrange

sys.modules[__name__] = lagrange
