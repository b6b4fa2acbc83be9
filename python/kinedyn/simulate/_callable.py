"""``kinedyn.simulate`` as type checkers see it (imported only under ``TYPE_CHECKING``): the package
module is callable at run time (see ``kinedyn/simulate/__init__.py``), which type checkers cannot
express for a module, so ``kd.simulate`` is typed as an object that is :func:`simulate` and holds
the package's public names."""

from __future__ import annotations

from . import control, core, systems, trajectory


class SimulatePackage:
    """``kd.simulate(system, t_span, x0, ...)`` and ``kd.simulate.PD`` etc."""

    __call__ = staticmethod(core.simulate)

    simulate = staticmethod(core.simulate)
    Trajectory = trajectory.Trajectory
    MechanicalSystem = systems.MechanicalSystem
    SimulationError = core.SimulationError
    SimulationOverflowError = core.SimulationOverflowError
    NonFiniteTorqueError = core.NonFiniteTorqueError
    SimulationTruncatedWarning = core.SimulationTruncatedWarning
    FIXED_METHODS = core.FIXED_METHODS
    ADAPTIVE_METHODS = core.ADAPTIVE_METHODS
    PD = control.PD
    PDGravity = control.PDGravity
    ComputedTorque = control.ComputedTorque
    FunctionController = control.FunctionController
    Reference = control.Reference
    Constant = control.Constant
    Cubic = control.Cubic
    Quintic = control.Quintic
    Fourier = control.Fourier


simulate = SimulatePackage()
