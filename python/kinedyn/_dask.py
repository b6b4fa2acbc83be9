"""Dask arrays through Robot's batched methods (docs/scale.md).

Every batched numeric method of :class:`kinedyn.Robot` is wrapped by :func:`batched`. When none of
its arguments is a ``dask.array.Array`` the wrapper costs one dictionary lookup and calls the method
as before; dask is never imported here (a robot works without it installed). When one is, the call
becomes a lazy ``dask.array`` built with ``blockwise``: one task per chunk of states, each calling
the very same method on a NumPy block, so the numbers are those of the in-process batch.

What travels to a worker is the robot's *description* (pickled once per call, a Robot drops its
native model when pickled), wrapped in a :class:`_RobotByContent` that is unpickled on the worker
through a per-process cache keyed by the description's SHA-256: each worker process unpickles the
description and builds the native model once, whatever the number of chunks or calls.
"""

from __future__ import annotations

import functools
import inspect
import os
import pickle
import sys
import threading
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from .ik.solve import IKBatchResult

if TYPE_CHECKING:
    from .robot import Robot

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["batched", "is_dask_array", "process_cache_info"]


def _dask_array_type() -> type | None:
    """``dask.array.Array`` if dask.array was imported by someone, else None (never imports it)."""
    module = sys.modules.get("dask.array")
    return getattr(module, "Array", None) if module is not None else None


def is_dask_array(x: Any) -> bool:
    """Whether ``x`` is a ``dask.array.Array``, without importing dask."""
    array_type = _dask_array_type()
    return array_type is not None and isinstance(x, array_type)


# ------------------------------------------------------------------ the per-process robot cache
_CACHE: dict[str, Robot] = {}
_CACHE_LOCK = threading.Lock()
_UNPICKLED: dict[str, int] = {}  # digest -> how many times this process unpickled the description


def _robot_from_cache(digest: str, payload: bytes) -> _RobotByContent:
    """Unpickling side of :class:`_RobotByContent`: the robot of this process for ``digest``."""
    with _CACHE_LOCK:
        robot = _CACHE.get(digest)
        if robot is None:
            robot = _CACHE[digest] = pickle.loads(payload)
            _UNPICKLED[digest] = _UNPICKLED.get(digest, 0) + 1
    return _RobotByContent(robot, digest, payload)


def process_cache_info() -> dict:
    """This process's cache of robots received by dask tasks: ``pid``, and per description digest
    how many times it was unpickled (``unpickled``, 1 when the cache works) and whether its native
    model is built (``built``). Ask every worker with ``client.run(process_cache_info)``."""
    with _CACHE_LOCK:
        return {
            "pid": os.getpid(),
            "unpickled": dict(_UNPICKLED),
            "built": {d: "_model" in r.__dict__ for d, r in _CACHE.items()},
        }


class _RobotByContent:
    """A robot that pickles as its description plus the description's hash; unpickled, it is the
    one robot of the receiving process with that hash (built once there)."""

    __slots__ = ("robot", "digest", "payload")

    def __init__(self, robot: Robot, digest: str, payload: bytes):
        self.robot, self.digest, self.payload = robot, digest, payload

    @classmethod
    def of(cls, robot: Robot) -> _RobotByContent:
        import hashlib  # OpenSSL's hashes load only when a robot goes to dask

        payload = pickle.dumps(robot, protocol=pickle.HIGHEST_PROTOCOL)
        return cls(robot, hashlib.sha256(payload).hexdigest(), payload)

    def __reduce__(self):
        return _robot_from_cache, (self.digest, self.payload)

    def __dask_tokenize__(self):
        return self.digest


# ------------------------------------------------------------------ the dispatch
_MODULES = sys.modules
_DASK_ARRAY = "dask.array"


def _any_dask(values: tuple) -> bool:
    array_type = _MODULES[_DASK_ARRAY].Array
    for value in values:  # a plain loop: a generator costs more than the check
        if isinstance(value, array_type):
            return True
    return False


def batched(*state_args: str, native: bool = False, errors: Callable | None = None) -> Callable[[F], F]:
    """Decorate a Robot method whose arguments ``state_args`` are (N, ...) batches of states: with a
    dask array among them it returns a lazy dask array (a tuple of them for tuple results).

    The wrapper is generated with the method's own parameters (no ``*args``/``**kwargs`` repacking):
    these methods run in control loops, and without dask imported the added cost is one dictionary
    lookup and one plain call.

    ``native=True`` declares that the method's body is the native model's method of the same name
    called with the same arguments, ``return self._model.NAME(args)``; the wrapper then makes that
    call itself instead of calling the method (one Python frame per call instead of two: a single
    state's call is a few hundred nanoseconds, issue 30). ``errors``: the body maps a RuntimeError
    of that call by ``raise errors(self, e) from None``. The method itself still serves dask's chunks
    (``__wrapped__``), and tests/test_api_native_forward.py checks that both give the same."""

    def decorate(method: F) -> F:
        signature = inspect.signature(method)
        parameters = list(signature.parameters.values())
        if any(p.kind is not p.POSITIONAL_OR_KEYWORD for p in parameters) or not set(state_args) <= set(
            signature.parameters
        ):
            raise TypeError(f"batched: {method.__name__} must take plain parameters including {state_args}")
        defaults = {f"_default_{p.name}": p.default for p in parameters if p.default is not p.empty}
        header = ", ".join(p.name if p.default is p.empty else f"{p.name}=_default_{p.name}" for p in parameters)
        names = ", ".join(p.name for p in parameters[1:])
        states = ", ".join(state_args) + ("," if len(state_args) == 1 else "")
        self_name = parameters[0].name
        call = f"{self_name}._model.{method.__name__}({names})" if native else f"_method({self_name}, {names})"
        if errors is not None:
            body = f"    try:\n        return {call}\n    except RuntimeError as e:\n        raise _errors({self_name}, e) from None\n"
        else:
            body = f"    return {call}\n"
        if errors is not None and not native:
            raise TypeError(f"batched: {method.__name__}: errors= describes a native=True body")
        source = (
            f"def {method.__name__}({header}):\n"
            f"    if _DASK_ARRAY in _MODULES and _any_dask(({states})):\n"
            f"        return _lazy_call(_method, _signature, _state_args, {self_name}, ({names}{',' if len(parameters) == 2 else ''}), {{}})\n"
            + body
        )
        namespace = {
            "_DASK_ARRAY": _DASK_ARRAY,
            "_MODULES": _MODULES,
            "_any_dask": _any_dask,
            "_lazy_call": _lazy_call,
            "_method": method,
            "_signature": signature,
            "_state_args": state_args,
            "_errors": errors,
            **defaults,
        }
        exec(compile(source, f"<kinedyn._dask.batched {method.__name__}>", "exec"), namespace)
        wrapper = functools.wraps(method)(namespace[method.__name__])
        wrapper.__kinedyn_batched__ = state_args  # type: ignore[attr-defined]
        wrapper.__kinedyn_native__ = native  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate


def _check_chunks(name: str, x) -> None:
    if x.ndim < 2:
        raise ValueError(
            f"{name} is a dask array of shape {x.shape}: dask inputs must be batches of states, "
            f"(N, ...) with the states along axis 0 (for one state pass a NumPy array)"
        )
    for axis in range(1, x.ndim):
        if len(x.chunks[axis]) > 1:
            fix = ", ".join(f"{a}: -1" for a in range(1, x.ndim))
            raise ValueError(
                f"{name} is chunked along axis {axis} (chunks {x.chunks[axis]}), the per-state axis of "
                f"shape {x.shape[1:]}: chunk only along the states (axis 0), e.g. {name}.rechunk({{{fix}}})"
            )


def _lazy_call(method, signature: inspect.Signature, state_args: Sequence[str], robot: Robot, args, kwargs):
    import dask.array as da

    bound = signature.bind(robot, *args, **kwargs)
    bound.apply_defaults()
    arguments = dict(bound.arguments)
    del arguments["self"]
    if arguments.get("out") is not None:
        raise ValueError("out= cannot be used with dask inputs: the result is a new lazy dask array")
    arguments.pop("out", None)

    lazy = {name: arguments[name] for name in arguments if is_dask_array(arguments[name])}
    wrong = sorted(set(lazy) - set(state_args))
    if wrong:
        raise TypeError(
            f"{method.__name__}: {', '.join(wrong)} cannot be a dask array (only {', '.join(state_args)} can)"
        )
    for name, x in lazy.items():
        _check_chunks(name, x)
    names = list(lazy)
    first = lazy[names[0]]
    for name in names[1:]:
        if lazy[name].shape[0] != first.shape[0]:
            raise ValueError(
                f"{method.__name__}: {names[0]} has {first.shape[0]} states but {name} has {lazy[name].shape[0]}"
            )
    # the states' chunks are those of the first dask input; the others follow, and the per-state
    # axes are one chunk each
    arrays = [lazy[names[0]].astype(np.float64)] + [
        lazy[name].astype(np.float64).rechunk({0: first.chunks[0], **{a: -1 for a in range(1, lazy[name].ndim)}})
        for name in names[1:]
    ]
    # NumPy batch arguments (N, ...) become dask arrays with the same chunks; others travel as they are
    fixed = {k: v for k, v in arguments.items() if k not in lazy}
    for name in state_args:
        v = fixed.get(name)
        if (
            v is not None
            and np.ndim(v) >= 2
            and np.shape(v)[0] == first.shape[0]
            and not (name == "f_ext" and np.ndim(v) == 2)
        ):
            arrays.append(da.from_array(np.asarray(v, dtype=np.float64), chunks=(first.chunks[0],) + np.shape(v)[1:]))
            names.append(name)
            del fixed[name]

    # the shape and dtype of one state's result, from a probe at one state (numbers never used)
    probe_args = dict(fixed)
    for name, x in zip(names, arrays):
        probe_args[name] = np.zeros((1,) + x.shape[1:])
    if "q" in names:
        probe_args["q"] = robot.neutral()[None] if arrays[names.index("q")].shape[1:] == (robot.n,) else probe_args["q"]
    probe = method(robot, **probe_args)
    results = probe if isinstance(probe, tuple) else (probe,)
    shapes = [np.shape(r)[1:] for r in results]

    carrier = _RobotByContent.of(robot)
    block = functools.partial(_block, carrier, method.__name__, tuple(names), fixed, len(results))
    states = "s"
    letters = iter("abcdefghijklmnopqrtuvwxyz")
    pairs: list[Any] = []
    for x in arrays:
        pairs += [x, states + "".join(next(letters) for _ in range(1, x.ndim))]
    if len(results) == 1:
        out_axes = "".join(next(letters) for _ in shapes[0])
        new_axes = dict(zip(out_axes, shapes[0]))
    else:  # tuple results: packed into one (N, total) block, sliced back out lazily below
        sizes = [int(np.prod(s)) for s in shapes]
        out_axes = next(letters)
        new_axes = {out_axes: sum(sizes)}
    out = da.blockwise(
        block,
        states + out_axes,
        *pairs,
        new_axes=new_axes,
        concatenate=True,
        dtype=np.float64,
        align_arrays=False,
        name=f"kinedyn-{method.__name__}-{carrier.digest[:8]}-" + da.core.tokenize(*arrays, fixed),
    )
    if len(results) == 1:
        return out
    parts, start = [], 0
    for size, shape in zip(sizes, shapes):
        parts.append(out[:, start : start + size].reshape((out.shape[0],) + tuple(shape)))
        start += size
    return tuple(parts)


def _block(carrier: _RobotByContent, method_name: str, names: tuple, fixed: dict, n_results: int, *blocks):
    """One chunk of states through the NumPy method, on whatever process runs the task."""
    robot = carrier.robot
    method = getattr(type(robot), method_name).__wrapped__
    result = method(robot, **fixed, **dict(zip(names, blocks)))
    if n_results == 1:
        return np.asarray(result, dtype=np.float64)
    return np.concatenate([np.asarray(r, dtype=np.float64).reshape(len(blocks[0]), -1) for r in result], axis=1)


# ------------------------------------------------------------------ batch inverse kinematics
def lazy_inverse_kinematics(robot: Robot, target, q0, mask, method: str, respect_limits: bool, options: dict):
    """``robot.inverse_kinematics`` of a dask batch of targets, (N, 4, 4) poses or (N, 3) positions:
    an ``IKBatchResult`` whose ``q`` (N, n), ``success``, ``position_error``, ``orientation_error``
    and ``iterations`` (N,) are lazy dask arrays chunked as the targets. ``q0`` may be one (n,) start
    or an (N, n) batch (NumPy or dask). The closed forms give the NumPy batch's answers; the numeric
    solver draws its random restarts per chunk (from ``seed`` and the index in the chunk), so where
    restarts are needed it may find other, equally valid, solutions than one NumPy call."""
    import dask.array as da

    _check_chunks("target", target)
    if target.shape[1:] not in ((4, 4), (3,)):
        raise ValueError(
            f"target must be a batch of 4x4 poses (N, 4, 4) or positions (N, 3), got a dask array of shape {target.shape}"
        )
    target = target.astype(np.float64)
    arrays, names = [target], ["target"]
    n = robot.nq  # a configuration's size (7 for a free-flyer)
    if q0 is not None and (is_dask_array(q0) or np.ndim(q0) == 2):
        q0 = q0 if is_dask_array(q0) else da.from_array(np.asarray(q0, dtype=np.float64), chunks=(target.chunks[0], -1))
        _check_chunks("q0", q0)
        if q0.shape != (target.shape[0], n):
            raise ValueError(
                f"q0 must be one start (nq,) = ({n},) or one per target ({target.shape[0]}, {n}), got {q0.shape}"
            )
        arrays.append(q0.astype(np.float64).rechunk({0: target.chunks[0], 1: -1}))
        names.append("q0")
        q0 = None
    # the solver's name, from a probe at the neutral pose (the numbers are not used)
    neutral = robot.pose(robot.neutral()[None], options.get("frame"))
    probe = robot.inverse_kinematics(
        neutral if target.ndim == 3 else neutral[:, :3, 3], q0, mask, method, respect_limits, **options
    )
    fixed = {"q0": q0, "mask": mask, "method": method, "respect_limits": respect_limits, **options}
    carrier = _RobotByContent.of(robot)
    block = functools.partial(_ik_block, carrier, tuple(names), fixed)
    pairs: list[Any] = [target, "s" + "ab"[: target.ndim - 1]]
    if len(arrays) > 1:
        pairs += [arrays[1], "sc"]
    packed = da.blockwise(
        block,
        "sz",
        *pairs,
        new_axes={"z": n + 4},
        concatenate=True,
        dtype=np.float64,
        align_arrays=False,
        name="kinedyn-inverse_kinematics-" + carrier.digest[:8] + "-" + da.core.tokenize(*arrays, fixed),
    )
    return IKBatchResult(
        q=packed[:, :n],
        success=packed[:, n] > 0.5,
        position_error=packed[:, n + 1],
        orientation_error=packed[:, n + 2],
        iterations=packed[:, n + 3].astype(np.int64),
        solver=probe.solver,
    )


def _ik_block(carrier: _RobotByContent, names: tuple, fixed: dict, *blocks):
    arguments = dict(fixed, **dict(zip(names, blocks)))
    solve = type(carrier.robot).inverse_kinematics
    result = solve(
        carrier.robot,
        arguments.pop("target"),
        arguments.pop("q0"),
        arguments.pop("mask"),
        arguments.pop("method"),
        arguments.pop("respect_limits"),
        **arguments,
    )
    columns = [result.success, result.position_error, result.orientation_error, result.iterations]
    return np.concatenate(
        [np.asarray(result.q, dtype=np.float64)] + [np.asarray(c, dtype=np.float64)[:, None] for c in columns], axis=1
    )


def dask_targets(target, q0):
    """NumPy targets with a dask batch of starts q0: the targets chunked as q0."""
    import dask.array as da  # optional and heavy: only a dask batch of starts gets here

    target = np.asarray(target, dtype=np.float64)
    return da.from_array(target, chunks=(q0.chunks[0],) + target.shape[1:])
