"""``kinedyn.symbolic.regressor``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.regressor`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import regressor

sys.modules[__name__] = regressor
