"""``kinedyn.symbolic.translate``, the path the documentation uses, is :mod:`kinedyn.symbolic.backends.walker`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .backends import walker

sys.modules[__name__] = walker
