"""``kinedyn.symbolic.casadi_export``, the path the documentation uses, is :mod:`kinedyn.symbolic.backends.casadi`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .backends import casadi

sys.modules[__name__] = casadi
