"""The properties of a :class:`kinedyn.symbolic.LagrangianSystem` are decided beside its equations, in
:mod:`kinedyn.symbolic.systems.system_properties`; ``kinedyn.analysis`` names the function as before."""

from ..symbolic.systems.system_properties import check_system_properties

__all__ = ["check_system_properties"]
