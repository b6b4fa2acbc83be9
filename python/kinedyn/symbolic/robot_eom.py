"""``kinedyn.symbolic.robot_eom``, the path the documentation uses, is :mod:`kinedyn.symbolic.systems.robot_eom`: this module
makes the old path name that module itself (so its attributes, and patches of them, are shared)."""

import sys

from .systems import robot_eom

sys.modules[__name__] = robot_eom
