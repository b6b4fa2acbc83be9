"""``kinedyn.symbolic.simplify``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.simplify`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import simplify

sys.modules[__name__] = simplify
