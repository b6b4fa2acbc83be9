"""Symbolic engine (SymPy): equations of motion of robots and of any Lagrangian system.

- :func:`equations_of_motion` (also ``Robot.equations_of_motion``): Euler-Lagrange with every step
  (Spong ch. 9) or the customised symbolic Newton-Euler model (Khalil & Dombre).
- :class:`EquationsOfMotion`: M, C, g, tau, Christoffel symbols, K, P, L, H, steps, regressor,
  LaTeX/Markdown/MathML, generated code.
- :class:`LagrangianSystem`: equations from K and P, from bodies, or from L directly, with generalised
  and non-conservative forces, holonomic and Pfaffian constraints (LaValle §13.4), Hamiltonian form.
"""

from .eom import EquationsOfMotion, Step, equations_of_motion
from .simplify import simplify_trig
from .system import LagrangianSystem, coordinates

__all__ = ["equations_of_motion", "EquationsOfMotion", "LagrangianSystem", "Step", "coordinates", "simplify_trig"]
