"""The sliders of a drawing of a robot with closed loops (docs/closed-loops.md, "Drawings"): one per
independent coordinate (``robot.independent_joints``), the other joints solved by projection onto
the loops (``robot.project_configuration(q, hold=sliders)``).

The live viewer solves each slider position as it moves. A static page (the report, an animation)
cannot run the solver, so the configurations are solved here when the page is written, on a grid of
each slider's values, and the page's sliders step from one solved configuration to the next:

- one or two independent coordinates (a four-bar, Spong's five-bar): every combination, a grid of
  ``GRID_1D`` or ``GRID_2D`` x ``GRID_2D`` intervals (fewer when the grid would hold more than
  ``NUMBERS`` numbers);
- three or more (a Delta robot, the parallelogram arm): a 1-D sweep of each from the drawn
  configuration, the others held there (``SWEEP`` positions each).

Each position is solved from its neighbours already solved, walking outward from the drawn
configuration (a continuation with a tangent predictor, ``_predict``: it stays on the assembly
branch it starts on, through a configuration where two branches meet too). A position the projection cannot close is left out (``None``): a crank that cannot turn
all the way round, a singular configuration the solver does not pass.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["loop_sliders", "LiveLoop", "GRID_1D", "GRID_2D", "NUMBERS", "SWEEP", "CLOSED"]

GRID_1D = 180  # intervals over a slider's range: 2 degrees over a full turn
GRID_2D = 72  # intervals per slider of a 2-D grid: 5 degrees, at most 73 x 73 configurations
NUMBERS = 40_000  # at most this many numbers in a 2-D grid (nq per configuration): fewer intervals for a large nq
SWEEP = 120  # intervals of each 1-D sweep (three or more sliders): 3 degrees
CLOSED = 1e-10  # a solved configuration is kept when its largest loop residual is below this


def _starts(robot) -> dict:
    starts, start = {}, 0
    for j in robot.joints:
        starts[j.name] = start
        start += j.nq
    return starts


def _velocity_columns(robot, names: list) -> list:
    """The velocity column of each named 1-DOF joint."""
    columns, start = {}, 0
    for j in robot.joints:
        columns[j.name] = start
        start += j.nv
    return [columns[name] for name in names]


def _values(q0: float, lo: float, hi: float, intervals: int) -> tuple[np.ndarray, int]:
    """The slider's positions: ``q0 + h k`` inside ``[lo, hi]`` (so the drawn value is one of them),
    ``h = (hi - lo) / intervals``; and the index of ``q0``."""
    h = (hi - lo) / intervals
    below = int(math.floor((q0 - lo) / h + 1e-9))
    above = int(math.floor((hi - q0) / h + 1e-9))
    return q0 + h * np.arange(-below, above + 1), below


def _project(robot, starts: np.ndarray, hold: list) -> np.ndarray:
    """Each row of ``starts`` projected onto the loops with ``hold`` fixed; NaN rows where it fails
    (one batch call; one call per state when the batch fails somewhere)."""
    try:
        out = np.atleast_2d(robot.project_configuration(starts, hold=hold))
    except ValueError:
        out = np.full_like(starts, np.nan)
        for k, s in enumerate(starts):
            try:
                out[k] = robot.project_configuration(s, hold=hold)
            except ValueError:
                pass
    ok = np.all(np.isfinite(out), axis=1)
    if ok.any():
        residual = np.abs(np.atleast_2d(robot.loop_residual(out[ok]))).max(axis=1)
        out[np.flatnonzero(ok)[residual >= CLOSED]] = np.nan
    return out


def _predict(robot, qs: np.ndarray, held: list, moved: int, delta: float, free: int) -> np.ndarray:
    """The tangent predictor of a continuation (Allgower & Georg, Numerical Continuation Methods,
    ch. 2): from each closed configuration of ``qs``, the first-order step along the closed motions
    (the null space ``N`` of ``J``, its ``free`` last right singular vectors) that moves the held
    velocity column ``held[moved]`` by ``delta`` and the other held ones not at all. On the branch
    the walk is on, whatever the other branches through a nearby singular configuration (the
    five-bar's parallelogram folded flat): the projection then corrects only its second-order error,
    where a start at the last point with one coordinate moved leaves the branch to the projection."""
    jac = np.atleast_3d(robot.loop_jacobian(qs)).reshape(len(qs), -1, robot.nv)
    null = np.swapaxes(np.linalg.svd(jac)[2][:, robot.nv - free :, :], 1, 2)  # (N, nv, free)
    target = np.zeros((len(qs), len(held), 1))
    target[:, moved] = delta
    step = null @ (np.linalg.pinv(null[:, held, :]) @ target)
    return np.asarray(robot.integrate(qs, step[..., 0]), dtype=float).reshape(qs.shape)


def _walk(robot, lines: np.ndarray, hold: list, entries: list, columns: list, axis: int, values, ref: int, free: int):
    """(N, len(values), nq): each closed configuration of ``lines`` (N, nq; its q[entries[axis]] at
    ``values[ref]``) carried along ``values`` of that coordinate, both ways from ``ref``, each
    position predicted from the one before it and projected with the sliders' joints ``hold`` held (all N lines in
    one batch per step)."""
    out = np.full((len(lines), len(values), lines.shape[1]), np.nan)
    out[:, ref] = lines
    for direction in (1, -1):
        previous, k = lines, ref + direction
        while 0 <= k < len(values):
            alive = np.all(np.isfinite(previous), axis=1)
            if not alive.any():
                break
            here = previous[alive]
            starts = _predict(robot, here, columns, axis, values[k] - values[k - direction], free)
            starts[:, entries[axis]] = values[k]  # exactly the slider's position
            out[np.flatnonzero(alive), k] = _project(robot, starts, hold)
            previous, k = out[:, k], k + direction
    return out


def _listed(states: np.ndarray) -> list:
    """Rows as lists, rounded to 1e-12 (a third shorter in JSON; the residual is then measured on
    what the page holds), a row with no closed configuration as None (JSON null)."""
    return [np.round(row, 12).tolist() if np.all(np.isfinite(row)) else None for row in states]


def loop_sliders(robot, q, reach: float = 1.0) -> dict | None:
    """What a static page needs to move a robot with loops by its independent coordinates, solved
    here (module docstring); None for a robot without loops, or when ``q`` is not closed (then the
    page keeps a slider per joint)."""
    if not getattr(robot, "loops", ()):
        return None
    q = np.asarray(q, dtype=float)
    try:
        if np.abs(robot.loop_residual(q)).max() >= CLOSED:
            return None
        names = robot.independent_joints(q)
        jac = robot.loop_jacobian(q)
    except ValueError:  # loops the core cannot hold (reduced mimic joints): a slider per joint
        return None
    rank = int(np.linalg.matrix_rank(jac, tol=1e-9 * max(1.0, float(np.abs(jac).max())))) if jac.size else 0
    starts = _starts(robot)
    joints = {j.name: j for j in robot.joints}
    entries = [starts[name] for name in names]
    mode = "grid" if len(names) <= 2 else "sweeps"
    square = min(GRID_2D, int(math.sqrt(NUMBERS / robot.nq)) - 1)
    intervals = {0: GRID_1D, 1: GRID_1D, 2: square}.get(len(names), SWEEP)
    axes, refs = [], []
    for name, e in zip(names, entries):
        revolute = joints[name].kind == "revolute"
        span = math.pi if revolute else reach
        lo, hi = float(robot.lower_limits[e]), float(robot.upper_limits[e])
        lo = lo if math.isfinite(lo) else q[e] - span
        hi = hi if math.isfinite(hi) else q[e] + span
        values, ref = _values(float(q[e]), lo, hi, intervals)
        axes.append(values)
        refs.append(ref)
    free = robot.nv - rank
    columns = _velocity_columns(robot, names)
    if mode == "grid" and len(names) == 2:
        line = _walk(robot, q[None], names, entries, columns, 0, axes[0], refs[0], free)[0]
        states = _walk(robot, line, names, entries, columns, 1, axes[1], refs[1], free).reshape(-1, robot.nq)
        solved = [_listed(states)]
    elif names:
        solved = [
            _listed(_walk(robot, q[None], names, entries, columns, k, values, ref, free)[0])
            for k, (values, ref) in enumerate(zip(axes, refs))
        ]
    else:
        solved = []
    held = [s for states in solved for s in states if s is not None]
    residual = float(np.abs(robot.loop_residual(np.asarray(held))).max()) if held else 0.0
    positions = sum(len(states) for states in solved)
    return {
        "mode": mode,
        "joints": names,
        "q": entries,
        "revolute": [joints[name].kind == "revolute" for name in names],
        "values": [np.round(v, 12).tolist() for v in axes],  # as the states are
        "reference": refs,
        "states": solved,  # grid: one list, row-major over the sliders; sweeps: one list per slider
        "free": robot.nv - rank,  # the mechanism's degrees of freedom at q
        "positions": positions,
        "unreachable": positions - len(held),
        "residual": residual,
        "note": _note(robot, names, mode, axes, robot.nv - rank, positions - len(held), residual),
    }


def _note(robot, names, mode, axes, free, unreachable, residual) -> str:
    """What the page says about its sliders: what moves them, what was solved, what is not drawn."""
    if not names:
        return (
            f"This robot has closed loops and no 1-DOF joint among its independent coordinates: it has no "
            f"slider here ({free} degrees of freedom, all in multi-DOF joints)."
        )
    listed = ", ".join(names)

    def step(values, name) -> str:
        h = values[1] - values[0] if len(values) > 1 else 0.0
        joint = next(j for j in robot.joints if j.name == name)
        return f"{math.degrees(h):.3g}°" if joint.kind == "revolute" else f"{h:.3g} m"

    if mode == "grid" and len(names) == 2:
        grid = (
            f"every combination of {len(axes[0])} x {len(axes[1])} positions (steps of "
            f"{step(axes[0], names[0])} and {step(axes[1], names[1])})"
        )
    elif mode == "grid":
        grid = f"{len(axes[0])} positions (steps of {step(axes[0], names[0])})"
    else:
        grid = (
            f"{', '.join(str(len(a)) for a in axes)} positions, each slider swept with the others at the drawn "
            "configuration (moving one slider puts the others back there)"
        )
    text = (
        f"Closed loops: each slider moves an independent coordinate ({listed}) and the other joints follow, "
        f"solved by projection onto the loops (holding {listed}) when the page was written, at {grid}. "
        f"Largest loop residual of those configurations: {residual:.1e}. Nothing is interpolated: a slider "
        "steps from one solved configuration to the next."
    )
    if unreachable:
        text += (
            f" {unreachable} positions have no closed configuration the solver reached from its neighbours "
            "(a coordinate that cannot turn all the way, a singular configuration): there the drawing stays "
            "where it was and says so."
        )
    multi = [j.name for j in robot.joints if j.is_multi_dof]
    if multi:
        left = f"the other {free - len(names)} degrees of freedom of the mechanism and " if free > len(names) else ""
        text += (
            f" No slider moves {left}the multi-DOF joints ({', '.join(multi)}): they stay where the solver "
            "puts them (least-norm steps)."
        )
    return text


class LiveLoop:
    """The live viewer's sliders of a robot with loops: ``joints`` (the independent coordinates at
    the closed configuration it starts from) and ``move(q, k, value)``, the closed configuration
    with slider k at ``value``, solved from ``q`` (the tangent predictor, then the projection with
    every slider held, as the page's grid), or None where the projection does not close the loops."""

    def __init__(self, robot, q):
        self.robot = robot
        self.joints = robot.independent_joints(q)
        jac = robot.loop_jacobian(q)
        rank = int(np.linalg.matrix_rank(jac, tol=1e-9 * max(1.0, float(np.abs(jac).max())))) if jac.size else 0
        self.free = robot.nv - rank
        self.entries = [_starts(robot)[name] for name in self.joints]
        self.columns = _velocity_columns(robot, self.joints)

    def move(self, q, k: int, value: float) -> np.ndarray | None:
        q = np.asarray(q, dtype=float)
        try:
            start = _predict(self.robot, q[None], self.columns, k, value - q[self.entries[k]], self.free)
        except (ValueError, np.linalg.LinAlgError):
            start = q[None].copy()
        start[0, self.entries[k]] = value
        out = _project(self.robot, start, self.joints)[0]
        return out if np.all(np.isfinite(out)) else None
