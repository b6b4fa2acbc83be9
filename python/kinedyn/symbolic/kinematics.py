"""``kinedyn.symbolic.kinematics``, the path the documentation uses, is :mod:`kinedyn.symbolic.derive.kinematics`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .derive import kinematics

sys.modules[__name__] = kinematics
