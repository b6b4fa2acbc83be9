"""``kinedyn.symbolic.codegen``, the path the documentation uses, is :mod:`kinedyn.symbolic.backends.c_numpy`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .backends import c_numpy

sys.modules[__name__] = c_numpy
