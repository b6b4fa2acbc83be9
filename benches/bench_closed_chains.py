"""Closed-chain benchmark (issue 12 §5, third bullet; not a timed test).

SymPy mechanics' four-bar linkage (3 coordinates, 2 loop-closure constraints) in the same run:

- kinedyn: ``examples.four_bar_linkage().numeric_accelerations(params)`` (symbolic parts compiled
  entry by entry, KKT system solved with NumPy per call), and the symbolic ``phase_space()``;
- SymPy: ``KanesMethod`` with dependent speeds and ``LagrangesMethod`` with ``hol_coneqs`` (derive,
  then lambdify the mass matrix and forcing, solve with NumPy per call).

Set-up time (first and best of two runs: the first also pays one-time imports) and time per evaluation, with ratios. Before this change kinedyn's ``numeric()`` did not
finish in 600 s (the constrained system was inverted symbolically).

    PYTHONPATH=python python benches/bench_closed_chains.py [--evaluations N]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
import sympy as sp

from kinedyn.symbolic import examples

warnings.filterwarnings("ignore")

PARAMS = dict(l1=0.13, l2=0.24, l3=0.21, l4=0.34, rho=997.0)
Q = np.array([2.1, 0.6655470375077588, 2.527408138024188])
QD = np.array([0.2, -0.17963733938852067, 0.1309060540601612])


def sympy_four_bar(method: str):
    from sympy.physics.mechanics import (
        KanesMethod,
        LagrangesMethod,
        Lagrangian,
        Point,
        ReferenceFrame,
        RigidBody,
        dynamicsymbols,
        inertia,
    )

    q, u, t = dynamicsymbols("q1:4"), dynamicsymbols("u1:4"), dynamicsymbols._t
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho")
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    frames = [N.orientnew("F2", "Axis", [q[0], N.z])]
    frames.append(frames[0].orientnew("F3", "Axis", [q[1], frames[0].z]))
    frames.append(frames[1].orientnew("F4", "Axis", [q[2], frames[1].z]))
    joint = O.locatenew("J1", l1 / 2 * N.x)
    centres = []
    for k, (F, length) in enumerate(zip(frames, (l2, l3, l4))):
        centres.append(joint.locatenew(f"C{k + 2}", length / 2 * F.x))
        joint = joint.locatenew(f"J{k + 2}", length * F.x)
    loop = joint.pos_from(O) + l1 / 2 * N.x
    fh = sp.Matrix([loop.dot(N.x), loop.dot(N.y)])
    qdot = [x.diff(t) for x in q]
    params = [l1, l2, l3, l4, rho]
    values = [PARAMS[str(s)] for s in params]
    if method == "lagranges":
        for C in centres:
            C.set_vel(N, C.pos_from(O).dt(N))
        bodies = [
            RigidBody(f"B{k}", C, F, rho * L, (inertia(F, 0, 0, rho * L**3 / 12), C))
            for k, (C, F, L) in enumerate(zip(centres, frames, (l2, l3, l4)))
        ]
        lm = LagrangesMethod(Lagrangian(N, *bodies), q, hol_coneqs=fh, frame=N)
        lm.form_lagranges_equations()
        Mf = sp.lambdify([q, qdot, params], lm.mass_matrix_full, cse=True)
        ff = sp.lambdify([q, qdot, params], lm.forcing_full, cse=True)
        return lambda qv, qdv: np.linalg.solve(
            np.asarray(Mf(qv, qdv, values), float), np.asarray(ff(qv, qdv, values), float).ravel()
        )[3:6]
    to_u = dict(zip(qdot, u))
    frames[0].set_ang_vel(N, u[0] * N.z)
    frames[1].set_ang_vel(frames[0], u[1] * frames[0].z)
    frames[2].set_ang_vel(frames[1], u[2] * frames[1].z)
    for C in centres:
        C.set_vel(N, C.pos_from(O).dt(N).subs(to_u))
    bodies = [
        RigidBody(f"B{k}", C, F, rho * L, (inertia(F, 0, 0, rho * L**3 / 12), C))
        for k, (C, F, L) in enumerate(zip(centres, frames, (l2, l3, l4)))
    ]
    kane = KanesMethod(
        N,
        q_ind=[q[0]],
        u_ind=[u[0]],
        q_dependent=q[1:],
        u_dependent=u[1:],
        kd_eqs=[a - b for a, b in zip(qdot, u)],
        configuration_constraints=fh,
        velocity_constraints=fh.diff(t).subs(to_u),
    )
    kane.kanes_equations(bodies, [])
    Mf = sp.lambdify([q, u, params], kane.mass_matrix, cse=True)
    ff = sp.lambdify([q, u, params], kane.forcing, cse=True)
    return lambda qv, qdv: np.linalg.solve(
        np.asarray(Mf(qv, qdv, values), float), np.asarray(ff(qv, qdv, values), float).ravel()
    )


def timed(fn, repeat=2):
    """(result, (first, best) wall times of ``repeat`` runs): the first run also pays one-time
    imports; later ones profit from SymPy's cache."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return out, (times[0], min(times))


def per_call(f, evaluations):
    start = time.perf_counter()
    for _ in range(evaluations):
        f(Q, QD)
    return (time.perf_counter() - start) / evaluations


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evaluations", type=int, default=2000)
    args = parser.parse_args()
    acc, t_kd = timed(lambda: examples.four_bar_linkage().numeric_accelerations(PARAMS))
    kd_f = lambda q, qd: acc(0.0, q, qd)[0]
    _, t_ps = timed(lambda: examples.four_bar_linkage().phase_space())
    kane, t_kane = timed(lambda: sympy_four_bar("kanes"))
    lagr, t_lagr = timed(lambda: sympy_four_bar("lagranges"))
    e_kd, e_kane, e_lagr = (per_call(f, args.evaluations) for f in (kd_f, kane, lagr))
    agree = max(np.abs(kd_f(Q, QD) - kane(Q, QD)).max(), np.abs(kd_f(Q, QD) - lagr(Q, QD)).max())
    print("four-bar linkage (SymPy mechanics' test), one run; q'' agree to", f"{agree:.1e}")
    print(f"{'':28s}{'set-up first / best':>22s}{'per evaluation':>18s}")
    for label, (first, best), e in (
        ("kinedyn numeric (KKT)", t_kd, e_kd),
        ("kinedyn phase_space (sym.)", t_ps, None),
        ("SymPy KanesMethod", t_kane, e_kane),
        ("SymPy LagrangesMethod", t_lagr, e_lagr),
    ):
        print(f"{label:28s}{first:10.2f}s /{best:7.2f}s" + (f"{e * 1e6:15.1f} us" if e else f"{'-':>18s}"))
    t_kd, t_kane, t_lagr = t_kd[1], t_kane[1], t_lagr[1]
    print(
        f"ratios (SymPy / kinedyn): set-up (best) Kane {t_kane / t_kd:.2f}x, Lagrange {t_lagr / t_kd:.2f}x; "
        f"per evaluation Kane {e_kane / e_kd:.2f}x, Lagrange {e_lagr / e_kd:.2f}x"
    )


if __name__ == "__main__":
    main()
