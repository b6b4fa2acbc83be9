"""``kinedyn.symbolic.jax_backend``, the path the documentation uses, is :mod:`kinedyn.symbolic.backends.jax`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .backends import jax

sys.modules[__name__] = jax
