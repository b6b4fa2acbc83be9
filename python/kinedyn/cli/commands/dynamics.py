"""``kinedyn dynamics ROBOT [--q ... --qd ... --qdd ...]``: M, C, g and tau at a state (the native
core); forward dynamics with --tau; the derivatives of inverse dynamics with --derivatives."""

from __future__ import annotations

import numpy as np

from .. import app
from ..app import console, dof_labels, emit, esc, matrix_table, parse_q, q_labels, q_text
from ..options import robot_argument, state_arguments


def add_arguments(p) -> None:
    robot_argument(p)
    state_arguments(p, with_qd=True)
    p.add_argument("--qdd", nargs="+", type=float, metavar="QDD", help="joint accelerations for tau (default zeros)")
    p.add_argument(
        "--tau", nargs="+", type=float, metavar="TAU", help="joint torques/forces: also print the forward dynamics qdd"
    )
    p.add_argument("--derivatives", action="store_true", help="also print dtau/dq and dtau/dqd (analytical)")


def run(args) -> int:
    robot = app.robot(args)
    q = parse_q(args.q, robot, args.deg)
    qd = parse_q(args.qd, robot, args.deg, "--qd")
    qdd = parse_q(args.qdd, robot, args.deg, "--qdd")
    M, C, g = robot.mass_matrix(q), robot.coriolis_matrix(q, qd), robot.gravity_torque(q)
    payload = {
        "robot": robot.name,
        "q": q,
        "qd": qd,
        "qdd": qdd,
        "coordinate_labels": q_labels(robot),
        "velocity_labels": dof_labels(robot),
        "mass_matrix": M,
        "coriolis_matrix": C,
        "gravity_torque": g,
        "tau": robot.inverse_dynamics(q, qd, qdd),
        "kinetic_energy": robot.kinetic_energy(q, qd),
        "potential_energy": robot.potential_energy(q),
    }
    if args.tau is not None:
        tau = parse_q(args.tau, robot, False, "--tau")
        payload["applied_tau"] = tau
        payload["forward_dynamics_qdd"] = robot.forward_dynamics(q, qd, tau)
    if args.derivatives:
        payload["dtau_dq"], payload["dtau_dqd"], _ = robot.inverse_dynamics_derivatives(q, qd, qdd)

    def render():
        c = console()
        names = dof_labels(robot)
        c.print(
            f"[bold]{esc(robot.name)}[/bold] at q = {q_text(robot, q)}, qd = {np.array2string(qd, precision=6)}, qdd = {np.array2string(qdd, precision=6)}"
        )
        c.print(matrix_table("M(q), mass matrix", M, names, names))
        c.print(matrix_table("C(q, qd), Coriolis matrix (Christoffel symbols)", C, names, names))
        c.print(
            matrix_table(
                "g(q), gravity torque and tau = M qdd + C qd + g + friction",
                np.column_stack([g, payload["tau"]]),
                names,
                ["g", "tau"],
            )
        )
        c.print(
            f"kinetic energy {payload['kinetic_energy']:.6g} J, potential energy {payload['potential_energy']:.6g} J"
        )
        if args.tau is not None:
            c.print(
                f"forward dynamics: tau = {np.array2string(payload['applied_tau'], precision=6)} gives qdd = {np.array2string(payload['forward_dynamics_qdd'], precision=6)}"
            )
        if args.derivatives:
            c.print(matrix_table("dtau/dq", payload["dtau_dq"], names, names))
            c.print(matrix_table("dtau/dqd", payload["dtau_dqd"], names, names))

    emit(args, payload, render)
    return 0
