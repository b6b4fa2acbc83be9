"""``kinedyn simulate ROBOT``: simulate a built-in robot or a robot file under a controller."""

from __future__ import annotations

import warnings

import numpy as np

from ...simulate.control import make_controller
from ...simulate.core import ADAPTIVE_METHODS, SimulationError, SimulationTruncatedWarning, simulate
from ...simulate.loops_runner import closed_configuration
from .. import app
from ..app import console, emit, esc, parse_q
from ..options import OutputPath, positive_float, positive_int, robot_argument


def add_arguments(p) -> None:
    robot_argument(p)
    p.add_argument("--t", type=positive_float, default=5.0, help="simulated time in seconds (default 5)")
    p.add_argument(
        "--dt",
        type=positive_float,
        default=1e-3,
        help="step (fixed-step methods) or sample spacing (adaptive), s (default 1e-3)",
    )
    p.add_argument(
        "--method",
        default="auto",
        help="auto (default: rk4, or implicit where rk4 would be unstable at --dt), rk4, implicit, semi_implicit, euler, rk45, rk23, dop853, radau, bdf, lsoda",
    )
    p.add_argument(
        "--controller",
        default="none",
        choices=["none", "pd", "pdg", "ct"],
        help="none (free motion), pd, pdg (PD + gravity compensation), ct (computed torque along a quintic to --goal)",
    )
    p.add_argument("--goal", nargs="+", type=float, metavar="Q", help="set point / end of the quintic (default zeros)")
    p.add_argument(
        "--kp",
        nargs="+",
        type=float,
        default=None,
        metavar="KP",
        help="proportional gain: one for every joint or one per joint (default 100)",
    )
    p.add_argument(
        "--kd",
        nargs="+",
        type=float,
        default=None,
        metavar="KD",
        help="derivative gain: one for every joint or one per joint (default 20)",
    )
    p.add_argument(
        "--joint-limits",
        dest="joint_limits",
        action="store_true",
        help="honour the joint position limits (inelastic stops); default: free motion passes through them",
    )
    p.add_argument(
        "--time-budget",
        dest="time_budget",
        type=positive_float,
        default=None,
        metavar="S",
        help="stop after S seconds of wall-clock time and report the samples so far (default: no limit)",
    )
    p.add_argument(
        "--t-move",
        dest="t_move",
        type=positive_float,
        default=2.0,
        help="duration of the computed-torque quintic (default 2 s)",
    )
    p.add_argument(
        "--q",
        nargs="+",
        type=float,
        metavar="Q",
        help="initial joint values (default zeros; for a robot with closed loops, a closed configuration found from there)",
    )
    p.add_argument("--qd", nargs="+", type=float, metavar="QD", help="initial joint velocities (default zeros)")
    p.add_argument("--deg", action="store_true", help="revolute joint values are in degrees")
    p.add_argument(
        "--record-every", dest="record_every", type=positive_int, default=1, help="keep every k-th step (default 1)"
    )
    p.add_argument("--plot", metavar="PNG", action=OutputPath, help="write joints, torques and energy plots")
    p.add_argument("--animate", metavar="GIF|HTML", action=OutputPath, help="write a stick-figure animation")
    p.add_argument("--csv", metavar="CSV", action=OutputPath, help="write the samples as CSV")
    p.add_argument("--npz", metavar="NPZ", action=OutputPath, help="write the samples as a NumPy .npz")


def _gains(values, robot, flag: str):
    """``--kp 100`` (one for every joint) or ``--kp 100 50 ...`` (one per joint): None, a number or (n,)."""
    if values is None:
        return None
    g = np.array(values, dtype=float)
    if g.size not in (1, robot.n):
        raise ValueError(
            f"{flag} takes one gain for every joint or one per joint ({robot.n} for robot '{robot.name}': {', '.join(robot.joint_names)}), got {g.size}"
        )
    if not np.all(np.isfinite(g)) or np.any(g < 0):
        raise ValueError(f"{flag} gains must be finite and non-negative, got {np.array2string(g)}")
    return float(g[0]) if g.size == 1 else g


ENERGY_SCALE_BASIS = "max K + (max P - min P) over the run"


def energy_drift(traj) -> dict:
    """The energy change of a run, absolute and relative to an energy scale of the run itself.

    H(0) is no scale: the zero of the potential energy is arbitrary (H(0) = 0 for an arm starting at
    rest in its zero configuration, and "max |H - H(0)| / |H(0)|" was 1e290). The scale used is the
    energy the motion exchanges, max K + (max P - min P) over the samples, which does not depend on
    where P is zero. ``energy_drift_relative`` is None when that scale is 0 (nothing moves)."""
    H = traj.H
    drift = float(np.abs(H - H[0]).max(initial=0.0))
    K, P = traj.K, traj.P
    scale = float(np.max(K) + np.ptp(P)) if len(H) else 0.0
    return {
        "energy_drift": drift,
        "energy_scale": scale,
        "energy_scale_basis": ENERGY_SCALE_BASIS,
        "energy_drift_relative": drift / scale if scale > 0 else None,
    }


def run(args) -> int:
    robot = app.robot(args)
    q0 = parse_q(args.q, robot, args.deg, flag="--q")
    qd0 = parse_q(args.qd, robot, args.deg, flag="--qd")
    if robot.loops and args.q is None:
        # zeros rarely close a loop (and a linkage stretched flat is singular there): start closed
        q0 = closed_configuration(robot, q0)
    if robot.has_multi_dof_joints and args.controller != "none":
        raise ValueError(
            f"--controller {args.controller} steers joint coordinates to --goal; robot '{robot.name}' has multi-DOF joints, "
            "whose error needs the configuration difference (simulate it with --controller none, or from Python)"
        )
    goal = parse_q(args.goal, robot, args.deg, flag="--goal") if args.goal is not None else np.zeros(robot.n)
    kp, kd = _gains(args.kp, robot, "--kp"), _gains(args.kd, robot, "--kd")
    method = str(args.method).lower()
    if args.joint_limits and method in ADAPTIVE_METHODS:
        raise ValueError(
            f"--joint-limits needs a fixed-step --method (auto, rk4, implicit, semi_implicit, euler), not '{args.method}'"
        )
    controller = (
        None
        if args.controller == "none"
        else make_controller(robot, args.controller, q_goal=goal, kp=kp, kd=kd, T=min(args.t, args.t_move), q0=q0)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SimulationTruncatedWarning)  # said in the output below
        try:
            traj = simulate(
                robot,
                args.t,
                np.concatenate([q0, qd0]),
                controller=controller,
                method=args.method,
                dt=args.dt,
                record_every=args.record_every,
                progress=None if not args.json else False,
                joint_limits=args.joint_limits,
                time_budget=args.time_budget,
            )
        except SimulationError as e:  # name the command line's flags, not the Python arguments
            message = (
                str(e)
                .replace("(reduce dt, use method='implicit'", "(reduce --dt, use --method implicit")
                .replace("exceeds max_speed", "exceeds the speed limit 1e6")
            )
            raise SimulationError(
                message.replace("the samples before it are in error.trajectory", "no samples were written")
            ) from None
    H = traj.H
    files = {}
    if args.plot:
        import matplotlib  # a heavy optional dependency: loaded only to draw

        matplotlib.use("Agg")
        traj.plot(args.plot)
        files["plot"] = args.plot
    if args.animate:
        import matplotlib  # a heavy optional dependency: loaded only to draw

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
        **energy_drift(traj),
        "wall_time_s": traj.info.get("wall_time"),
        "method_choice": traj.info.get("method_choice"),
        "joint_limits": bool(args.joint_limits),
        "truncated": traj.info.get("truncated"),
        "loop_residual_max": traj.info.get("loop_residual_max"),
        "files": files,
    }

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: {args.t:g} s with {traj.method} (dt = {args.dt:g} s), controller {payload['controller']}, "
            f"{len(traj)} samples in {payload['wall_time_s']:.3g} s"
        )
        if payload["method_choice"]:
            c.print(f"  method {payload['method_choice']}")
        if payload["loop_residual_max"] is not None:
            c.print(
                f"  loops {', '.join(esc(loop.name) for loop in robot.loops)} held by projection after each step: "
                f"max |residual| {payload['loop_residual_max']:.3g} over the run"
            )
        if payload["truncated"]:
            c.print(f"  [bold yellow]cut short[/bold yellow]: {payload['truncated']}")
        c.print(f"  q(T)  = {np.array2string(traj.q[-1], precision=5)}")
        c.print(f"  qd(T) = {np.array2string(traj.qd[-1], precision=5)}")
        rel = payload["energy_drift_relative"]
        c.print(
            f"  energy H: {H[0]:.8g} J -> {H[-1]:.8g} J, max |H - H(0)| = {payload['energy_drift']:.3g} J"
            + (
                f" = {rel:.3g} x the energy scale {payload['energy_scale']:.4g} J ({payload['energy_scale_basis']})"
                if rel is not None
                else " (the arm does not move: no energy scale)"
            )
        )
        for k, v in files.items():
            c.print(f"  {k}: {esc(v)}")

    emit(args, payload, render)
    return 0
