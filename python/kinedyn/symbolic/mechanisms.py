"""``kinedyn.symbolic.mechanisms``, the path the documentation uses, is :mod:`kinedyn.symbolic.systems.mechanisms`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .systems import mechanisms

sys.modules[__name__] = mechanisms
