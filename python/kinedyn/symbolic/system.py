"""``kinedyn.symbolic.system``, the path the documentation uses, is :mod:`kinedyn.symbolic.systems.system`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .systems import system

sys.modules[__name__] = system
