"""The arguments of :func:`~kinedyn.simulate.simulate` checked and put in the form the runners take:
the method names, the system (a robot, or a mechanical system built from a Lagrangian one), the
initial state, the time grid, and the generalised forces (data ``u``, a function ``u(t, q, qd)``, a
controller; external wrenches ``f_ext``)."""

from __future__ import annotations

import math

import numpy as np

from .._arrays import real_array
from .errors import NonFiniteTorqueError
from .systems import MechanicalSystem

__all__ = [
    "FIXED_METHODS",
    "ADAPTIVE_METHODS",
    "METHOD_ALIASES",
    "is_robot",
    "as_mechanical",
    "coordinate_names",
    "split_state",
    "time_grid",
    "sampled_u",
    "u_at",
    "torque_sources",
    "external_wrenches",
]


FIXED_METHODS = ("rk4", "semi_implicit", "euler", "implicit")


ADAPTIVE_METHODS = {
    "rk45": "RK45",
    "rk23": "RK23",
    "dop853": "DOP853",
    "radau": "Radau",
    "bdf": "BDF",
    "lsoda": "LSODA",
}


METHOD_ALIASES = {
    "semi_implicit_euler": "semi_implicit",
    "symplectic_euler": "semi_implicit",
    "symplectic": "semi_implicit",
    "implicit_euler": "implicit",
}


def is_robot(system) -> bool:
    return hasattr(system, "_model") and hasattr(system, "forward_dynamics")


def as_mechanical(system, params, baumgarte, points) -> MechanicalSystem:
    if isinstance(system, MechanicalSystem):
        if baumgarte is not None:
            system.baumgarte = tuple(baumgarte)
        return system
    if hasattr(system, "euler_lagrange") and hasattr(system, "holonomic"):
        return MechanicalSystem.from_lagrangian(
            system, params=params, points=points, baumgarte=tuple(baumgarte) if baumgarte is not None else (10.0, 10.0)
        )
    raise TypeError(
        f"simulate needs a kinedyn.Robot, a kinedyn.symbolic.LagrangianSystem or a kinedyn.simulate.MechanicalSystem, got {type(system).__name__}"
    )


def coordinate_names(system) -> list:
    return list(system.joint_names) if hasattr(system, "joint_names") else list(system.names)


def split_state(x0, n: int, name: str, nq: int | None = None):
    """(q0, qd0) from x0 = concatenate([q0, qd0]): nq + n numbers (nq = n without multi-DOF joints)."""
    nq = n if nq is None else nq
    x = real_array(x0, "x0")  # TypeError for complex, text or integers beyond float64
    if x.ndim not in (1, 2) or x.shape[-1] != nq + n:
        size = f"2 n = {2 * n}" if nq == n else f"nq + nv = {nq} + {n}"
        raise ValueError(
            f"x0 must be concatenate([q0, qd0]) with {size} entries for '{name}' ({n} coordinates), "
            f"or a batch (N, {nq + n}); got shape {x.shape}"
        )
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 contains a non-finite value (NaN or inf)")
    return np.ascontiguousarray(x[..., :nq]), np.ascontiguousarray(x[..., nq:])


def time_grid(t_span, dt, method):
    try:
        if np.ndim(t_span) == 0:
            t0, t1 = 0.0, float(t_span)
        else:
            if len(t_span) != 2:
                raise ValueError
            t0, t1 = float(t_span[0]), float(t_span[1])
    except (TypeError, ValueError):
        raise ValueError(f"t_span must be a duration T or a pair (t0, t1) in seconds, got {t_span!r}") from None
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
        raise ValueError(f"t_span must end after it starts (t1 > t0), got ({t0}, {t1})")
    if dt is None:
        dt = 1e-3
    try:
        dt = float(dt)
    except (TypeError, ValueError):
        raise ValueError(f"dt must be a positive step in seconds, got {dt!r}") from None
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive step in seconds, got {dt}")
    dt = min(dt, t1 - t0)  # a step longer than the span: one step of the span
    ratio = (t1 - t0) / dt
    if not ratio < 2.0**53:  # beyond this, t0 + k dt no longer advances in float64 (and no run ends)
        raise ValueError(
            f"t_span ({t0}, {t1}) with dt = {dt} asks for {ratio:.3g} steps: more than 2**53; raise dt or shorten t_span"
        )
    steps = max(1, int(math.ceil(ratio - 1e-9)))
    return t0, t1, dt, steps


def sampled_u(u, n: int, steps: int, batch: int | None):
    """u as data: None -> None; (n,) constant -> (1, n); (steps, n) held; (steps + 1, n) linear;
    (N, S, n) per trajectory. Returns (array or None, linear)."""
    if u is None:
        return None, False
    a = np.asarray(u, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.shape[-1] != n:
        raise ValueError(f"u must give {n} generalised forces per sample, got shape {np.shape(u)}")
    if a.ndim == 3 and (batch is None or a.shape[0] != batch):
        raise ValueError(f"u of shape {a.shape} is per trajectory but the batch has {batch} initial states")
    rows = a.shape[-2]
    if rows not in (1, steps, steps + 1):
        raise ValueError(
            f"u has {rows} samples: give 1 (a constant), {steps} (one per step, held over it) or "
            f"{steps + 1} (one per sample time t0 + k dt, interpolated linearly)"
        )
    if not np.all(np.isfinite(a)):
        k = np.argwhere(~np.isfinite(a))[0]
        raise NonFiniteTorqueError(f"u contains a non-finite value at index {tuple(int(i) for i in k)}")
    return np.ascontiguousarray(a), rows == steps + 1 and rows > 1


def u_at(a: np.ndarray, linear: bool, t0: float, dt: float, k: int, t: float):
    """Sample of data-u for step k at time t (a: (S, n))."""
    rows = a.shape[0]
    if rows == 1:
        return a[0]
    k = min(k, rows - 1)
    if linear and k + 1 < rows:
        s = min(max((t - (t0 + k * dt)) / dt, 0.0), 1.0)
        return (1 - s) * a[k] + s * a[k + 1]
    return a[k]


def torque_sources(n: int, name: str, u_data, linear: bool, u_fn, controller, t0: float, dt: float):
    """``torque_for(index)`` -> ``torque(k, t, q, qd)``: the generalised force on trajectory ``index``
    at step ``k`` and time ``t``, the sum of the data ``u`` (:func:`sampled_u`; per trajectory when
    it is (N, S, n)), ``u_fn(t, q, qd)`` and ``controller(t, q, qd)``, each checked to be (n,)."""

    def checked(value, what, t):
        v = np.asarray(value, dtype=float)
        if v.shape != (n,):
            raise ValueError(
                f"{what} returned torques of shape {v.shape} at t = {t:g} s; {name} has {n} joints (shape ({n},))"
            )
        return v

    def torque_for(index):
        data = None if u_data is None else (u_data[index] if u_data.ndim == 3 else u_data)

        def torque(k, t, q, qd):
            tau = np.zeros(n)
            if data is not None:
                tau = tau + u_at(data, linear, t0, dt, k, t)
            if u_fn is not None:
                tau = tau + checked(u_fn(t, q, qd), "u", t)
            if controller is not None:
                tau = tau + checked(controller(t, q, qd), "the controller", t)
            return np.ascontiguousarray(tau, dtype=float)

        return torque

    return torque_for


def external_wrenches(f_ext, n: int, robot: bool):
    """``f_ext`` as a function ``(t, q, qd) -> (n, 6)`` link wrenches, or None: a function is kept, a
    constant (n, 6) array is checked (finite; robots only) and wrapped."""
    if callable(f_ext):
        return f_ext
    if f_ext is None:
        return None
    if not robot:
        raise ValueError(
            "f_ext applies to robots (wrenches on links); for a Lagrangian system put the generalised force in u"
        )
    fe = np.asarray(f_ext, dtype=float)
    if fe.shape != (n, 6) or not np.all(np.isfinite(fe)):
        raise ValueError(
            f"f_ext must be a finite (n, 6) = ({n}, 6) array of link wrenches, or a function of (t, q, qd)"
        )
    return lambda t, q, qd: fe
