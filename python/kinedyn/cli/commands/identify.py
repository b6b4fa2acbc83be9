"""``kinedyn identify ROBOT``: base inertial parameters (and friction) identified from a robot's log
(``--data``) or from a simulated Fourier excitation; ``--excite`` writes an optimised excitation."""

from __future__ import annotations

from rich.table import Table

from ..._ui.files import replacing
from ...analysis.excitation import excitation_condition, optimize_excitation, write_trajectory_csv
from ...analysis.experiment import CONTROLLERS, experiment_controller, load_reference
from ...analysis.identification import excitation, identify, simulate_measurements
from ...analysis.logs import load_log
from ...report.identification import write_identification_html
from .. import app
from ..app import console, emit, esc
from ..options import (
    InputPath,
    OutputPath,
    nonnegative_float,
    nonnegative_int,
    positive_float,
    positive_int,
    robot_argument,
)


def add_arguments(p) -> None:
    robot_argument(p)
    p.add_argument(
        "--noise", type=nonnegative_float, default=0.0, help="torque noise standard deviation, N m (default 0)"
    )
    p.add_argument("--harmonics", type=positive_int, default=5)
    p.add_argument("--period", type=positive_float, default=10.0, help="period of the excitation, s (default 10)")
    p.add_argument("--periods", type=positive_float, default=2.0, help="measured periods (default 2)")
    p.add_argument("--amplitude", type=nonnegative_float, default=0.6, help="joint excursion, rad or m (default 0.6)")
    p.add_argument("--rate", type=positive_float, default=100.0, help="sample rate, Hz (default 100)")
    p.add_argument("--weighted", action="store_true", help="weighted least squares (per-joint noise levels)")
    p.add_argument("--seed", type=nonnegative_int, default=0)
    p.add_argument(
        "--data",
        metavar="LOG",
        action=InputPath,
        help="identify from a log (CSV or NPZ: t, q1..qn, tau1..taun) instead of a simulated excitation",
    )
    p.add_argument(
        "--friction",
        default="viscous+coulomb",
        help="friction terms estimated with --data: viscous, coulomb, asymmetric (a Coulomb level per direction), "
        "stribeck, offset joined by '+'; stribeck alone (viscous+coulomb+stribeck); none / known (default viscous+coulomb)",
    )
    p.add_argument("--offset", action="store_true", help="estimate a torque offset per joint (with --data)")
    p.add_argument(
        "--armature",
        action="store_true",
        help="estimate every joint's armature (reflected rotor inertia; by default only the geared joints')",
    )
    p.add_argument(
        "--delay",
        default=None,
        metavar="SECONDS|estimate",
        help="the torques' delay behind the positions: a number of seconds, or 'estimate' (within +-20 ms)",
    )
    p.add_argument(
        "--method",
        default="auto",
        choices=("auto", "ols", "wls", "irls", "iv", "didim"),
        help="estimator: ordinary, weighted or iteratively reweighted (robust) least squares; iv (instrumental "
        "variables) and didim (output error) for closed-loop data, which simulate the model under the controller that "
        "ran the experiment: a log does not hold it, so give --controller, --kp, --kd and --reference "
        "(default: iv with --controller, else ols, wls with --weighted)",
    )
    p.add_argument(
        "--controller",
        choices=CONTROLLERS,
        default=None,
        help="the controller that ran the experiment (with --data): pd (Kp e + Kd ed), pdg (PD + the model's "
        "gravity), ct (computed torque on the robot's model)",
    )
    p.add_argument("--kp", default=None, metavar="K|K1,..,Kn", help="the controller's proportional gains")
    p.add_argument("--kd", default=None, metavar="K|K1,..,Kn", help="the controller's derivative gains")
    p.add_argument(
        "--reference",
        metavar="CSV",
        action=InputPath,
        help="the trajectory the controller tracked (t, q1..qn[, qd1.., qdd1..], as --excite saves it), on the log's clock",
    )
    p.add_argument(
        "--control-period", type=positive_float, default=1e-3, help="the controller's period, s (default 0.001)"
    )
    p.add_argument(
        "--min-speed",
        type=nonnegative_float,
        default=0.0,
        help="leave out the rows where a joint moves slower than this (rad/s): stick and Coulomb's jump",
    )
    p.add_argument(
        "--smoothing", type=positive_float, default=None, help="smooth the Coulomb sign as tanh(qd / SMOOTHING), rad/s"
    )
    p.add_argument(
        "--consistent",
        action="store_true",
        help="physically consistent parameters (pseudo-inertias positive definite; an SDP through cvxpy)",
    )
    p.add_argument(
        "--validate",
        metavar="LOG",
        action=InputPath,
        help="a second log: torque RMS and R^2 per joint of the identified model",
    )
    p.add_argument(
        "--cutoff", type=positive_float, default=None, help="low-pass cut-off, Hz (default: 5 x the motion's bandwidth)"
    )
    p.add_argument(
        "--decimate",
        type=positive_int,
        default=None,
        help="keep every k-th sample after filtering (default: rate / (5 cut-off))",
    )
    p.add_argument(
        "--excite",
        metavar="CSV",
        action=OutputPath,
        help="write an optimised excitation (min cond(Y_base), at rest at both ends; --period, --harmonics, --rate) for a controller, and stop",
    )
    p.add_argument(
        "--plot", metavar="FILE", action=OutputPath, help="save measured vs predicted torques (PNG, PDF, SVG)"
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="HTML",
        action=OutputPath,
        default=None,
        help="write a self-contained HTML identification report (parameters, friction, rotor inertia, torque and residual plots)",
    )


def run(args) -> int:
    robot = app.robot(args)
    if args.excite:
        return _write_excitation(robot, args)
    if args.data:
        return _identify_from_log(robot, args)
    ref = excitation(robot, harmonics=args.harmonics, period=args.period, amplitude=args.amplitude, seed=args.seed)
    data = simulate_measurements(
        robot, ref, T=args.periods * args.period, rate=args.rate, noise=args.noise, seed=args.seed
    )
    result = identify(robot, data, weighted=args.weighted)
    payload = dict(robot=robot.name, samples=len(data.t), noise=args.noise, **result.to_dict())
    if args.output:
        payload["report"] = str(write_identification_html(result, args.output))

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: {len(result.names)} base parameters from {len(data.t)} samples "
            f"({args.periods:g} periods of a {args.harmonics}-harmonic Fourier excitation, noise {args.noise:g}); "
            f"cond(W) = {result.condition_number:.4g}, {'weighted' if args.weighted else 'ordinary'} least squares"
        )
        t = Table(title_justify="left")
        for col in ("parameter", "estimate", "std", "true", "error", "error / std"):
            t.add_column(col, justify="right")
        true = result.true_values
        assert true is not None  # identify() on a known robot always has the true values
        # noise-free data: the fit is exact to round-off, so the std is round-off as well and an error
        # over it is a ratio of two rounding noises (it read 40 like a 40-sigma failure)
        exact = result.exact
        for k, nm in enumerate(result.names):
            e = result.estimates[k] - true[k]
            t.add_row(
                esc(nm),
                f"{result.estimates[k]:.8g}",
                f"{result.std[k]:.2g}",
                f"{true[k]:.8g}",
                f"{e:.2g}",
                f"{e / result.std[k]:.2f}" if result.std[k] > 0 and not exact else "-",
            )
        c.print(t)
        if exact:
            c.print(
                "noise-free data: the fit reproduces the torques to round-off, so the errors and std are round-off "
                "and error / std is not shown (give --noise to see the estimator's statistics)"
            )
        if result.dropped:
            c.print(f"not excited (zero regressor columns on the data): {esc(', '.join(result.dropped))}")

    emit(args, payload, render)
    return 0


def _write_excitation(robot, args) -> int:
    """``kinedyn identify ROBOT --excite traj.csv``: an optimised excitation for a controller."""
    ref = optimize_excitation(robot, period=args.period, harmonics=args.harmonics, seed=args.seed)
    write_trajectory_csv(ref, args.excite, rate=args.rate)
    cond = excitation_condition(robot, ref)
    random_cond = excitation_condition(
        robot, excitation(robot, harmonics=args.harmonics, period=args.period, amplitude=args.amplitude, seed=args.seed)
    )
    payload = dict(
        robot=robot.name,
        trajectory=str(args.excite),
        period=args.period,
        harmonics=args.harmonics,
        rate=args.rate,
        condition_number=cond,
        random_condition_number=random_cond,
    )

    def render():
        console().print(
            f"[bold]{esc(robot.name)}[/bold]: excitation of {args.harmonics} harmonics, period {args.period:g} s, "
            f"at rest at both ends, written to {esc(str(args.excite))} at {args.rate:g} Hz; "
            f"cond(Y_base) {cond:.4g} (a random Fourier excitation of the same band: {random_cond:.4g})"
        )

    emit(args, payload, render)
    return 0


def _identify_from_log(robot, args) -> int:
    """``kinedyn identify ROBOT --data log.csv``: a real robot's log (see docs/analysis.md)."""
    options = dict(cutoff=args.cutoff, decimate=args.decimate)
    log = load_log(args.data, n=robot.n, **options)
    delay = args.delay
    if delay is not None and delay.strip().lower() != "estimate":
        try:
            delay = float(delay)
        except ValueError:
            raise ValueError(f"--delay: a number of seconds or 'estimate', got {delay!r}") from None
    controller = _controller(robot, args)
    result = identify(
        robot,
        log,
        controller=controller,
        control_period=args.control_period,
        min_speed=args.min_speed,
        weighted=args.weighted,
        friction=args.friction,
        consistent=args.consistent,
        smoothing=args.smoothing,
        offset=args.offset,
        armature=True if args.armature else None,
        delay=delay,
        method=args.method,
    )
    payload = dict(robot=robot.name, data=str(args.data), cutoff_hz=log.cutoff, rate_hz=log.rate, **result.to_dict())
    check = None
    if args.validate:
        check = result.validate(args.validate, **options)
        payload["validation"] = check.to_dict()
    if args.plot:
        fig = result.plot(args.validate or log)
        with replacing(args.plot) as tmp:  # atomic; the same extension, so the same format
            fig.savefig(tmp)
        payload["plot"] = str(args.plot)
    if args.output:
        payload["report"] = str(write_identification_html(result, args.output, args.validate, **options))

    def render():
        c = console()
        c.print(
            f"[bold]{esc(robot.name)}[/bold]: {len(result.names)} base parameters and {len(result.friction_names)} friction coefficients "
            f"from {len(log)} samples of {esc(str(args.data))} (cut-off {log.cutoff or 0:.3g} Hz, {log.rate:.4g} Hz after decimation); "
            f"cond(W) = {result.condition_number:.4g}, method {result.method}"
            + (", physically consistent (SDP)" if result.consistent else "")
            + (f"; torques {1e3 * result.delay:.3g} ms behind the positions" if result.delay else "")
        )
        t = Table(title_justify="left")
        for col in ("parameter", "estimate", "std", "std %"):
            t.add_column(col, justify="right")
        for nm, e, sd, rel in zip(result.names, result.estimates, result.std, result.relative_std):
            t.add_row(esc(nm), f"{e:.6g}", f"{sd:.2g}", f"{rel:.3g}")
        for nm, e, sd in zip(result.friction_names, result.friction_estimates, result.friction_std):
            t.add_row(esc(nm), f"{e:.6g}", f"{sd:.2g}", f"{100 * sd / max(abs(e), 1e-300):.3g}")
        c.print(t)
        for s in result.stribeck:
            c.print(
                f"{esc(s['joint'])}: Stribeck velocity {s['velocity']:.4g} rad/s (std {s['velocity_std']:.2g}), "
                f"static friction {', '.join(f'{v:.4g}' for v in s['static'])} N m"
            )
        loop = result.closed_loop
        if loop is not None:
            c.print(
                f"{result.method}: {result.iterations} simulation(s) under the experiment's controller, "
                + ("converged" if loop["converged"] else "not converged")
                + f" (last change {100 * loop['last_change']:.3g} %, tolerance {100 * loop['tolerance']:.3g} %)"
            )
        for note in result.notes:
            c.print(esc(note))
        assert result.identifiability is not None
        for group in result.identifiability.groups:
            c.print(f"not separable by the data (only a combination is identified): {esc(', '.join(group))}")
        grouped = [r for r in result.rotors if r.armature is None]
        if grouped:
            c.print(
                "armatures r² J_m grouped with link parameters (not identifiable on their own): "
                + "; ".join(f"{esc(r.joint)} into {esc(', '.join(r.grouped_into))}" for r in grouped)
            )
        if args.output:
            c.print(f"report written to {esc(str(args.output))}")
        if check is not None:
            v = Table(title=f"validation on {esc(str(args.validate))}", title_justify="left")
            for col in ("joint", "torque RMS", "R²"):
                v.add_column(col, justify="right")
            for j, (rms, r2) in enumerate(zip(check.rms, check.r2)):
                v.add_row(str(j + 1), f"{rms:.4g}", f"{r2:.5f}")
            c.print(v)

    emit(args, payload, render)
    return 0


def _gain_list(text, option: str):
    try:
        return [float(v) for v in str(text).split(",")]
    except ValueError:
        raise ValueError(f"{option}: a number or a comma-separated list of numbers, got {text!r}") from None


def _controller(robot, args):
    """The experiment's controller from --controller/--kp/--kd/--reference (None without them);
    iv and didim without it: say what is missing, as the log cannot hold it."""
    given = [
        o
        for o, v in (
            ("--controller", args.controller),
            ("--kp", args.kp),
            ("--kd", args.kd),
            ("--reference", args.reference),
        )
        if v is not None
    ]
    if not given:
        if args.method in ("iv", "didim"):
            raise ValueError(
                f"--method {args.method} simulates the identified model under the controller that ran the experiment, "
                "and a log does not hold it: give --controller pd|pdg|ct, --kp, --kd and --reference TRAJ.csv "
                "(the trajectory it tracked), or use --method ols|wls|irls"
            )
        return None
    missing = [o for o in ("--controller", "--kp", "--kd", "--reference") if o not in given]
    if missing:
        raise ValueError(f"the experiment's controller needs {', '.join(missing)} as well (given: {', '.join(given)})")
    reference = load_reference(args.reference, robot.n)
    return experiment_controller(
        robot, args.controller, _gain_list(args.kp, "--kp"), _gain_list(args.kd, "--kd"), reference
    )
