"""``kinedyn.symbolic.latex``, the path the documentation uses, is :mod:`kinedyn.symbolic.render.latex`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .render import latex

sys.modules[__name__] = latex
