"""``kinedyn.symbolic.cse``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.cse`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import cse

sys.modules[__name__] = cse
