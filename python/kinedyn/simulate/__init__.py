"""Simulation and control: :func:`simulate` integrates the equations of motion of a robot (fixed-step
schemes in the Rust core, adaptive ones with SciPy) or of a Lagrangian system (constraints
stabilised by Baumgarte's method) and returns a :class:`Trajectory`; :mod:`.control` holds the
controllers and reference trajectories. See docs/simulation.md."""

import sys
import types

from .control import PD, ComputedTorque, Constant, Cubic, Fourier, FunctionController, PDGravity, Quintic, Reference
from .core import (
    ADAPTIVE_METHODS,
    FIXED_METHODS,
    NonFiniteTorqueError,
    SimulationError,
    SimulationOverflowError,
    SimulationTruncatedWarning,
    simulate,
)
from .systems import MechanicalSystem
from .trajectory import Trajectory

__all__ = [
    "simulate",
    "Trajectory",
    "MechanicalSystem",
    "SimulationError",
    "SimulationOverflowError",
    "NonFiniteTorqueError",
    "SimulationTruncatedWarning",
    "FIXED_METHODS",
    "ADAPTIVE_METHODS",
    "PD",
    "PDGravity",
    "ComputedTorque",
    "FunctionController",
    "Reference",
    "Constant",
    "Cubic",
    "Quintic",
    "Fourier",
]


# ``kd.simulate(...)`` calls :func:`simulate` while ``kd.simulate.PD`` etc. stay reachable: the package
# module is made callable (a function of the same name would shadow the package in ``kinedyn``).
def _make_callable() -> None:
    class _SimulateModule(types.ModuleType):
        def __call__(self, *args, **kwargs):
            return simulate(*args, **kwargs)

    sys.modules[__name__].__class__ = _SimulateModule


_make_callable()
