"""The tutorial elbow arm's inverse kinematics as SymPy expressions, derived step by step.

The arm (``kinedyn.robots.elbow_3r``; Spong, Hutchinson & Vidyasagar, *Robot Modeling and
Control*, Table 3.3 layout) in standard DH:

====  =====  ====  ===  =======
link  theta  d     a    alpha
1     q1     L1    0    +90 deg
2     q2     0     L2   0
3     q3     0     L3   0
====  =====  ====  ===  =======

Derivation (written here from the forward kinematics, then checked against it numerically by
:meth:`ElbowSolution.verify` and by the tests):

1. Forward kinematics of the tool point o3 (product of the three DH transforms):
   ``x = c1 (L2 c2 + L3 c23)``, ``y = s1 (L2 c2 + L3 c23)``, ``z = L1 + L2 s2 + L3 s23``.
2. Joints 2 and 3 move the tool in the vertical plane that joint 1 turns, so ``(x, y)`` is
   parallel to ``(c1, s1)``: ``theta1 = atan2(y, x)`` with horizontal reach ``rho = +r``, or
   ``theta1 = atan2(y, x) + pi`` with ``rho = -r`` (reaching over the base), ``r = sqrt(x^2 + y^2)``.
3. In that plane the arm is a planar 2R arm: ``rho = L2 c2 + L3 c23``, ``s = z - L1 = L2 s2 + L3 s23``.
4. Law of cosines: ``rho^2 + s^2 = L2^2 + L3^2 + 2 L2 L3 c3``, so
   ``D = c3 = (x^2 + y^2 + (z - L1)^2 - L2^2 - L3^2) / (2 L2 L3)``, ``theta3 = atan2(+-sqrt(1 - D^2), D)``
   (reachable iff ``|D| <= 1``).
5. ``theta2 = atan2(s, rho) - atan2(L3 s3, L2 + L3 c3)`` (the direction to the tool minus the angle the
   forearm adds).

Four branches: shoulder front/back (step 2) x elbow up/down (step 4). "Elbow up" means the elbow
lies above the shoulder-tool line: ``theta3 < 0`` on the front branch, ``theta3 > 0`` on the back.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

__all__ = ["ElbowSolution", "symbolic_elbow_solution"]


@dataclass
class ElbowSolution:
    """theta_i as SymPy expressions of ``x, y, z`` and ``L1, L2, L3``, one dict per branch."""

    x: sp.Symbol
    y: sp.Symbol
    z: sp.Symbol
    L1: sp.Symbol
    L2: sp.Symbol
    L3: sp.Symbol
    D: sp.Expr
    branches: list  # [{"name": str, "theta1": expr, "theta2": expr, "theta3": expr}]
    steps: list = field(default_factory=list)  # [(explanation, sympy.Eq)]
    reachable: sp.Expr | None = None

    @property
    def symbols(self) -> tuple:
        return (self.x, self.y, self.z, self.L1, self.L2, self.L3)

    def evaluate(self, x, y, z, L1=3.0, L2=2.0, L3=1.0) -> np.ndarray:
        """(4, 3) joint angles of the branches at a point (rows of NaN for an unreachable point)."""
        values = dict(zip(self.symbols, (x, y, z, L1, L2, L3)))
        D = float(self.D.subs(values))
        if abs(D) > 1.0 + 1e-12:
            return np.full((len(self.branches), 3), np.nan)
        # at the boundary |D| = 1 rounding can leave a tiny imaginary part: keep the real part
        return np.array(
            [[complex(sp.N(b[k].subs(values))).real for k in ("theta1", "theta2", "theta3")] for b in self.branches]
        )

    def lambdify(self):
        """A NumPy function ``f(x, y, z, L1, L2, L3) -> (4, 3)``."""
        exprs = [[b["theta1"], b["theta2"], b["theta3"]] for b in self.branches]
        return sp.lambdify(self.symbols, exprs, "numpy")

    def forward(self):
        """The forward kinematics (x, y, z) of step 1 as expressions of theta1..3."""
        t1, t2, t3 = sp.symbols("theta1 theta2 theta3")
        reach = self.L2 * sp.cos(t2) + self.L3 * sp.cos(t2 + t3)
        return (t1, t2, t3), (
            sp.cos(t1) * reach,
            sp.sin(t1) * reach,
            self.L1 + self.L2 * sp.sin(t2) + self.L3 * sp.sin(t2 + t3),
        )

    def verify(self, point=(1.0, 0.2, 0.5), lengths=(3.0, 2.0, 1.0)) -> float:
        """Largest distance between ``point`` and the forward kinematics of every branch's angles."""
        thetas, fk = self.forward()
        f = sp.lambdify(thetas + self.symbols[3:], fk, "numpy")
        worst = 0.0
        for row in self.evaluate(*point, *lengths):
            worst = max(worst, float(np.linalg.norm(np.array(f(*row, *lengths)) - np.asarray(point))))
        return worst

    def to_latex(self) -> str:
        lines = [sp.latex(eq) + r"\quad\text{(" + text + ")}" for text, eq in self.steps]
        for b in self.branches:
            lines.append(
                r"\text{"
                + b["name"]
                + r":}\; "
                + ", ".join(rf"\theta_{k} = {sp.latex(b[f'theta{k}'])}" for k in (1, 2, 3))
            )
        return " \\\\\n".join(lines)

    def __str__(self) -> str:
        out = [f"D = cos(theta3) = {self.D}"]
        for b in self.branches:
            out.append(f"{b['name']}: theta1 = {b['theta1']}, theta2 = {b['theta2']}, theta3 = {b['theta3']}")
        return "\n".join(out)


def symbolic_elbow_solution(L1=None, L2=None, L3=None) -> ElbowSolution:
    """The four branches of the elbow arm's inverse kinematics (see the module docstring).

    Link lengths default to positive symbols ``L1, L2, L3``; pass numbers to substitute them
    (e.g. the tutorial's ``3, 2, 1``)."""
    x, y, z = sp.symbols("x y z", real=True)
    s1, s2, s3 = sp.symbols("L1 L2 L3", positive=True)
    r = sp.sqrt(x**2 + y**2)
    s = z - s1
    D = (x**2 + y**2 + s**2 - s2**2 - s3**2) / (2 * s2 * s3)
    root = sp.sqrt(1 - D**2)
    c1, c2, c3, q1, q2, q3, rho = sp.symbols("c_1 c_2 c_3 theta1 theta2 theta3 rho", real=True)
    steps = [
        (
            "forward kinematics, step 1",
            sp.Eq(
                sp.Matrix([x, y, z]),
                sp.Matrix(
                    [
                        sp.cos(q1) * (s2 * sp.cos(q2) + s3 * sp.cos(q2 + q3)),
                        sp.sin(q1) * (s2 * sp.cos(q2) + s3 * sp.cos(q2 + q3)),
                        s1 + s2 * sp.sin(q2) + s3 * sp.sin(q2 + q3),
                    ]
                ),
            ),
        ),
        ("waist angle, step 2", sp.Eq(q1, sp.atan2(y, x))),
        (
            "planar 2R in the arm's plane, step 3",
            sp.Eq(
                sp.Matrix([rho, z - s1]),
                sp.Matrix([s2 * sp.cos(q2) + s3 * sp.cos(q2 + q3), s2 * sp.sin(q2) + s3 * sp.sin(q2 + q3)]),
            ),
        ),
        ("law of cosines, step 4", sp.Eq(sp.cos(q3), D)),
        ("shoulder angle, step 5", sp.Eq(q2, sp.atan2(z - s1, rho) - sp.atan2(s3 * sp.sin(q3), s2 + s3 * sp.cos(q3)))),
    ]
    branches = []
    for front in (True, False):
        th1 = sp.atan2(y, x) if front else sp.atan2(y, x) + sp.pi
        reach = r if front else -r
        for sign in (1, -1):
            th3 = sp.atan2(sign * root, D)
            # sin(theta3) = sign*root, cos(theta3) = D
            th2 = sp.atan2(s, reach) - sp.atan2(s3 * sign * root, s2 + s3 * D)
            up = (sign < 0) if front else (sign > 0)
            name = f"shoulder {'front' if front else 'back'}, elbow {'up' if up else 'down'}"
            branches.append({"name": name, "theta1": th1, "theta2": th2, "theta3": th3})
    reachable = sp.Le(sp.Abs(D), 1)
    sol = ElbowSolution(x, y, z, s1, s2, s3, D, branches, steps, reachable=reachable)
    given = {k: v for k, v in ((s1, L1), (s2, L2), (s3, L3)) if v is not None}
    if given:
        sol.D = sol.D.subs(given)
        sol.branches = [{k: (v.subs(given) if isinstance(v, sp.Basic) else v) for k, v in b.items()} for b in branches]
        sol.steps = [(t, e.subs(given)) for t, e in steps]
        sol.reachable = reachable.subs(given)
    return sol
