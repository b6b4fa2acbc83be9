"""Symbolic engine (SymPy): equations of motion of robots and of any Lagrangian system.

- :func:`equations_of_motion` (also ``Robot.equations_of_motion``): Euler-Lagrange with every step
  (Spong ch. 9) or the customised symbolic Newton-Euler model (Khalil & Dombre).
- :class:`EquationsOfMotion`: M, C, g, tau, Christoffel symbols, K, P, L, H, steps, regressor,
  LaTeX/Markdown/MathML, generated code.
- :func:`pose`, :func:`jacobian`: a frame's symbolic pose and geometric Jacobian in the joint symbols
  of the equations of motion; :func:`jacobian_inverse`, :func:`tool_velocity`, :func:`joint_torques`.
- :class:`LagrangianSystem`: equations from K and P, from bodies, or from L directly, with generalised
  and non-conservative forces, holonomic and Pfaffian constraints (LaValle §13.4), Hamiltonian form.
- :mod:`~kinedyn.symbolic.mechanisms`: :func:`change_coordinates` (a drive map q = A p), closed chains
  from serial trees and loop closures (:func:`closed_chain`, :func:`closed_chain_system`,
  :func:`loop_closure`), :func:`decoupling_condition` (Spong §9.4).
"""

from .derive.kinematics import (
    JacobianInverse,
    abbreviate,
    jacobian,
    jacobian_inverse,
    joint_symbols,
    joint_torques,
    pose,
    tool_velocity,
)
from .derive.simplify import simplify_trig
from .eom import EquationsOfMotion
from .steps import Step
from .systems.mechanisms import (
    change_coordinates,
    closed_chain,
    closed_chain_system,
    decoupling_condition,
    loop_closure,
    tree_equations,
)
from .systems.robot_eom import equations_of_motion
from .systems.system import LagrangianSystem, coordinates

__all__ = [
    "equations_of_motion",
    "EquationsOfMotion",
    "LagrangianSystem",
    "Step",
    "coordinates",
    "simplify_trig",
    "pose",
    "jacobian",
    "jacobian_inverse",
    "JacobianInverse",
    "tool_velocity",
    "joint_torques",
    "abbreviate",
    "joint_symbols",
    "change_coordinates",
    "closed_chain",
    "closed_chain_system",
    "decoupling_condition",
    "loop_closure",
    "tree_equations",
]
