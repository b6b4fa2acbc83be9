"""Derivation: equations of motion of robots (Lagrange, Newton-Euler) and of Lagrangian systems, closed
chains, symbolic kinematics, the regressor, common-subexpression form and trigonometric simplification."""
