"""``kinedyn.symbolic.newton_euler``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.newton_euler`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import newton_euler

sys.modules[__name__] = newton_euler
