"""How a simulation fails: the exceptions :func:`~kinedyn.simulate.simulate` raises, and the failure
record every runner (native, Python fixed-step, adaptive) fills in and :func:`raise_failure` turns
into one of them with the samples before it.

A failure record is a dict: ``step``, ``t``, ``joint`` (index or None), ``kind`` ("torque",
"diverged", "non_finite", "singular"), ``value`` and ``message``, the same fields as the core's
integrator reports (``kinedyn._core.integrate_fixed``)."""

from __future__ import annotations

from .._core import NonFiniteResultError
from ..native.errors import nonphysical_note

__all__ = [
    "SimulationError",
    "NonFiniteTorqueError",
    "SimulationOverflowError",
    "SimulationTruncatedWarning",
    "StopRun",
    "failure_message",
    "raise_failure",
]


class SimulationError(RuntimeError):
    """A simulation stopped early. ``t``, ``step``, ``joint`` (index or None), ``index`` (the
    trajectory of a batch), ``kind`` and ``trajectory`` (the samples before the failure)."""

    def __init__(self, message, *, t=None, step=None, joint=None, index=None, kind=None, trajectory=None):
        super().__init__(message)
        self.t, self.step, self.joint, self.index, self.kind, self.trajectory = t, step, joint, index, kind, trajectory


class NonFiniteTorqueError(SimulationError, ValueError):
    """The controller or torque input produced NaN or infinity."""


class SimulationOverflowError(SimulationError, NonFiniteResultError):
    """The state's numbers overflowed float64 (finite inputs, but a configuration or velocity far
    beyond any robot's): also a ``kinedyn.NonFiniteResultError``, hence a ``ValueError``."""


class SimulationTruncatedWarning(RuntimeWarning):
    """A simulation reached its ``time_budget`` (wall-clock seconds) and returned the samples it had;
    ``traj.info["truncated"]`` says where it stopped."""


class StopRun(Exception):
    """Raised inside a Python runner's loop to end a trajectory; ``failure`` is its failure record."""

    def __init__(self, failure):
        super().__init__(failure["kind"])
        self.failure = failure


def failure_message(system_name, names, f: dict, index, steps, unit_speed="rad/s or m/s") -> tuple:
    j = f.get("joint")
    # the joint by name only: the core counts from 0, the default names from 1 ("joint 2 ('q3')")
    where = f" at joint '{names[j]}'" if j is not None and j < len(names) else ""
    at = f"t = {f['t']:.6g} s (step {f['step']} of {steps})"
    which = f" (trajectory {index} of the batch)" if index is not None else ""
    kind = f["kind"]
    if kind == "torque":
        return (
            NonFiniteTorqueError,
            f"the controller / input returned a non-finite torque ({f['value']}){where} at {at}{which}",
        )
    if kind == "diverged":
        return SimulationError, (
            f"simulation of '{system_name}' blew up at {at}{which}: speed {f['value']:.3g} {unit_speed}{where} exceeds "
            f"max_speed; the samples before it are in error.trajectory (reduce dt, use method='implicit' for a stiff robot, check the gains / inputs)"
        )
    if kind == "non_finite":
        return (
            SimulationError,
            f"simulation of '{system_name}' blew up at {at}{which}: the state became non-finite{where}; the samples before it are in error.trajectory",
        )
    if kind == "singular":
        cls = SimulationOverflowError if "too large for float64" in (f["message"] or "") else SimulationError
        return cls, f"simulation of '{system_name}' stopped at {at}{which}: {f['message']}"
    return SimulationError, f"simulation of '{system_name}' stopped at {at}{which}: {f.get('message', '')}"


def raise_failure(system, names, failures, steps_done, traj_factory, steps):
    for index, f in enumerate(failures):
        if f is not None:
            cls, message = failure_message(
                getattr(system, "name", "system"), names, f, index if len(failures) > 1 else None, steps
            )
            if f["kind"] == "singular" and isinstance(f.get("joint"), int) and hasattr(system, "description"):
                message += nonphysical_note(system, f["joint"])  # a kept non-physical inertia can make M singular
            partial = traj_factory(index, int(steps_done[index]))
            raise cls(
                message,
                t=f["t"],
                step=f["step"],
                joint=f.get("joint"),
                index=index if len(failures) > 1 else None,
                kind=f["kind"],
                trajectory=partial,
            )
