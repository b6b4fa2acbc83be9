"""The numeric mechanical system the integrators take lives in :mod:`kinedyn.mechanical` (below both
the simulator and the symbolic engine, which compiles a ``LagrangianSystem`` into one); this path
keeps ``kinedyn.simulate.systems.MechanicalSystem`` importable."""

from ..mechanical import MechanicalSystem

__all__ = ["MechanicalSystem"]
