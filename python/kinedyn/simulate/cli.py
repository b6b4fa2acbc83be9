"""``kinedyn simulate ROBOT``: simulate a built-in robot or a robot file under a controller."""

from __future__ import annotations

import numpy as np

__all__ = ["add_simulate_commands", "cmd_simulate"]


def cmd_simulate(args) -> int:
    from ..cli import console, emit, esc, load_robot, parse_q
    from .. import robots
    from .control import make_controller
    from .core import simulate

    robot = load_robot(args.robot or robots.DEFAULT)
    q0 = parse_q(args.q, robot, args.deg)
    qd0 = parse_q(args.qd, robot, args.deg, "--qd")
    goal = parse_q(args.goal, robot, args.deg, "--goal") if args.goal is not None else np.zeros(robot.n)
    controller = None if args.controller == "none" else make_controller(robot, args.controller, q_goal=goal, kp=args.kp, kd=args.kd, T=min(args.t, args.t_move), q0=q0)
    traj = simulate(robot, args.t, np.concatenate([q0, qd0]), controller=controller, method=args.method, dt=args.dt,
                    record_every=args.record_every, progress=None if not args.json else False)
    H = traj.H
    files = {}
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        traj.plot(args.plot)
        files["plot"] = args.plot
    if args.animate:
        import matplotlib

        matplotlib.use("Agg")
        traj.animate(args.animate)
        files["animation"] = args.animate
    if args.csv:
        traj.to_csv(args.csv)
        files["csv"] = args.csv
    if args.npz:
        traj.to_npz(args.npz)
        files["npz"] = args.npz
    payload = {
        "robot": robot.name,
        "method": traj.method,
        "dt": args.dt,
        "t_final": float(traj.t[-1]),
        "samples": len(traj),
        "controller": getattr(controller, "name", "none") if controller is not None else "none",
        "q_final": traj.q[-1],
        "qd_final": traj.qd[-1],
        "goal": goal if controller is not None else None,
        "energy_initial": float(H[0]),
        "energy_final": float(H[-1]),
        "energy_drift_relative": float(np.abs(H - H[0]).max() / max(abs(H[0]), 1e-300)),
        "wall_time_s": traj.info.get("wall_time"),
        "files": files,
    }

    def render():
        c = console()
        c.print(f"[bold]{esc(robot.name)}[/bold]: {args.t:g} s with {traj.method} (dt = {args.dt:g} s), controller {payload['controller']}, "
                f"{len(traj)} samples in {payload['wall_time_s']:.3g} s")
        c.print(f"  q(T)  = {np.array2string(traj.q[-1], precision=5)}")
        c.print(f"  qd(T) = {np.array2string(traj.qd[-1], precision=5)}")
        c.print(f"  energy H: {H[0]:.8g} J -> {H[-1]:.8g} J (max relative change {payload['energy_drift_relative']:.3g})")
        for k, v in files.items():
            c.print(f"  {k}: {esc(v)}")

    emit(args, payload, render)
    return 0


def add_simulate_commands(subparsers) -> None:
    from ..cli import OutputPath, _robot_arg, positive_float, positive_int

    p = subparsers.add_parser("simulate", help="simulate a robot under a controller (RK4 in the native core by default)")
    _robot_arg(p)
    p.add_argument("--t", type=positive_float, default=5.0, help="simulated time in seconds (default 5)")
    p.add_argument("--dt", type=positive_float, default=1e-3, help="step (fixed-step methods) or sample spacing (adaptive), s (default 1e-3)")
    p.add_argument("--method", default="rk4", help="rk4, semi_implicit, euler, rk45, rk23, dop853, radau, bdf, lsoda (default rk4)")
    p.add_argument("--controller", default="none", choices=["none", "pd", "pdg", "ct"],
                   help="none (free motion), pd, pdg (PD + gravity compensation), ct (computed torque along a quintic to --goal)")
    p.add_argument("--goal", nargs="+", type=float, metavar="Q", help="set point / end of the quintic (default zeros)")
    p.add_argument("--kp", type=float, default=None, help="proportional gain (default 100)")
    p.add_argument("--kd", type=float, default=None, help="derivative gain (default 20)")
    p.add_argument("--t-move", dest="t_move", type=positive_float, default=2.0, help="duration of the computed-torque quintic (default 2 s)")
    p.add_argument("--q", nargs="+", type=float, metavar="Q", help="initial joint values (default zeros)")
    p.add_argument("--qd", nargs="+", type=float, metavar="QD", help="initial joint velocities (default zeros)")
    p.add_argument("--deg", action="store_true", help="revolute joint values are in degrees")
    p.add_argument("--record-every", dest="record_every", type=positive_int, default=1, help="keep every k-th step (default 1)")
    p.add_argument("--plot", metavar="PNG", action=OutputPath, help="write joints, torques and energy plots")
    p.add_argument("--animate", metavar="GIF|HTML", action=OutputPath, help="write a stick-figure animation")
    p.add_argument("--csv", metavar="CSV", action=OutputPath, help="write the samples as CSV")
    p.add_argument("--npz", metavar="NPZ", action=OutputPath, help="write the samples as a NumPy .npz")
    p.set_defaults(func=cmd_simulate)
