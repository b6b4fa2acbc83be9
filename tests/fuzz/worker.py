"""The fuzz worker: a long-lived subprocess that runs cases one at a time and classifies each.

Started by :class:`fuzz.runner.Worker` as ``python -m fuzz.worker``. It imports kinedyn, then limits
its own address space (``RLIMIT_AS``, $KD_FUZZ_MEMORY bytes) and reads length-prefixed pickled
:class:`~fuzz.strategies.Case` objects from stdin, answering each with a pickled result dict on the
original stdout (fd 1 is re-pointed at stderr so that prints from the library cannot corrupt the
protocol). Hangs and crashes are seen by the parent (timeout, death by a signal); everything a
case can raise is classified here.
"""

from __future__ import annotations

import dataclasses
import faulthandler
import math
import os
import pickle
import resource
import struct
import sys
import time
import warnings

import numpy as np

from .strategies import CANARY_ENV, MARKER_ENV, Case, make_robot

# outcome classes; the first two are the good ones
CLEAN = "clean_error"  # a loader's ValueError naming the file; an array call's ValueError/TypeError/MemoryError
SUCCESS = "success"  # loaded (and the first numeric calls were finite) / returned finite numbers
PANIC = "panic"  # pyo3_runtime.PanicException reached Python
CRASH = "crash"  # the worker died (signal, abort)
HANG = "hang"  # no answer within the time limit
MEMORY = "memory"  # a loader ran out of the memory limit (MemoryError, or Rust's allocation abort)
NONFINITE = "nonfinite"  # finite input, NaN/inf in the result
BAD_EXCEPTION = "bad_exception"  # a loader raised something other than ValueError; a call other than ValueError/TypeError/MemoryError
CODE_EXEC = "code_exec"  # the canary ran: a file's expression executed Python
NO_FILENAME = "no_filename"  # a loader's ValueError that does not name the file
REPEATED_NAME = "repeated_name"  # a loader's message that repeats the file name (a doubled prefix)
DEFERRED = "deferred"  # a file that loaded but failed at its first numeric call (the error belongs at load)
BAD_INPUT_ACCEPTED = (
    "bad_input_accepted"  # complex (non-zero imaginary part) or NaN/inf input, or duplicate YAML keys, accepted
)
VALID_REJECTED = "valid_rejected"  # an input valid as documented (an unmutated seed, a valid call) raised an error
DATA_LOSS = "data_loss"  # an output overwrote, or was allowed to be, a file the command reads (fuzz.surfaces)

CLASSES = (
    CLEAN,
    SUCCESS,
    PANIC,
    CRASH,
    HANG,
    MEMORY,
    NONFINITE,
    BAD_EXCEPTION,
    CODE_EXEC,
    NO_FILENAME,
    REPEATED_NAME,
    DEFERRED,
    BAD_INPUT_ACCEPTED,
    VALID_REJECTED,
    DATA_LOSS,
)
DEFECTS = CLASSES[2:]
FILE_NAME = "fuzzcase"  # basename (without extension) of the file each file case is written to


def _is_panic(e: BaseException) -> bool:
    return type(e).__name__ == "PanicException"


def _describe(e: BaseException) -> str:
    text = str(e)
    if len(text) > 600:
        text = text[:400] + f" ...({len(text)} chars)... " + text[-150:]
    return f"{type(e).__module__}.{type(e).__qualname__}: {text}"


def nonfinite(x, depth: int = 0) -> bool:
    """Whether a result holds NaN or inf anywhere (arrays, floats, tuples, dataclass/attribute values)."""
    if isinstance(x, np.ndarray):
        return x.dtype.kind in "fc" and not bool(np.all(np.isfinite(x)))
    if isinstance(x, (float, np.floating, complex, np.complexfloating)):
        return not np.isfinite(x)
    if isinstance(x, (bool, int, str, bytes, type(None), np.integer)):
        return False
    if depth > 2:
        return False
    if isinstance(x, (list, tuple)):
        return any(nonfinite(v, depth + 1) for v in x)
    if isinstance(x, dict):
        return any(nonfinite(v, depth + 1) for v in x.values())
    if dataclasses.is_dataclass(x):
        return any(nonfinite(getattr(x, f.name), depth + 1) for f in dataclasses.fields(x))
    if hasattr(x, "__dict__"):
        return any(nonfinite(v, depth + 1) for k, v in vars(x).items() if not k.startswith("_"))
    return False


def _input_problem(x, depth: int = 0):
    """'complex' or 'non-finite' when an argument holds such numbers (else None)."""
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "c" and np.any(x.imag != 0):
            return "complex"
        if x.dtype.kind in "fc" and not np.all(np.isfinite(x)):
            return "non-finite"
        if x.dtype == object and x.size:
            return _input_problem(list(x.reshape(-1)), depth + 1)
        return None
    if isinstance(x, complex) and x.imag != 0:
        return "complex"
    if isinstance(x, float) and not math.isfinite(x):
        return "non-finite"
    if isinstance(x, (list, tuple)) and depth < 3:
        for v in x:
            p = _input_problem(v, depth + 1)
            if p:
                return p
    if isinstance(x, dict) and depth < 3:
        return _input_problem(list(x.values()), depth + 1)
    return None


# ============================================================================ file cases
def _probe(robot):
    """The first numeric calls a user makes on a loaded numeric robot, at the neutral configuration."""
    if robot.is_symbolic:
        return SUCCESS, "loaded (symbolic)"
    inverted = [name for name, lo, hi in zip(robot.joint_names, robot.lower_limits, robot.upper_limits) if lo > hi]
    if inverted:  # accepted at load, wrong later (random_configuration, simulation with limits)
        return DEFERRED, f"loaded with lower > upper limits for joints {inverted}"
    q = robot.neutral()
    z = np.zeros(robot.n)
    calls = (
        ("forward_kinematics", lambda: robot.forward_kinematics(q)),
        ("mass_matrix", lambda: robot.mass_matrix(q)),
        ("inverse_dynamics", lambda: robot.inverse_dynamics(q, z, z)),
        ("gravity_torque", lambda: robot.gravity_torque(q)),
        ("random_configuration", lambda: robot.random_configuration(0)),
    )
    for name, call in calls:
        try:
            out = call()
        except MemoryError as e:
            return MEMORY, f"loaded; {name} at q = 0: {_describe(e)}"
        except Exception as e:
            return DEFERRED, f"loaded; {name} at q = 0: {_describe(e)}"
        except BaseException as e:
            return (PANIC if _is_panic(e) else BAD_EXCEPTION), f"loaded; {name} at q = 0: {_describe(e)}"
        if nonfinite(out):
            return NONFINITE, f"loaded; {name} at q = 0 is not finite"
    return SUCCESS, f"loaded (n = {robot.n})"


def run_file(case: Case, folder: str):
    import kinedyn as kd

    path = os.path.join(folder, FILE_NAME + case.ext)
    with open(path, "wb") as f:
        f.write(case.data if isinstance(case.data, bytes) else case.data.encode("utf-8", "surrogatepass"))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = kd.load(path)
    except ValueError as e:
        message = str(e)
        if FILE_NAME + case.ext not in message:
            return NO_FILENAME, _describe(e)
        if message.count(path) > 1:
            return REPEATED_NAME, _describe(e)
        return CLEAN, _describe(e)
    except MemoryError as e:
        return MEMORY, _describe(e)
    except BaseException as e:
        return (PANIC if _is_panic(e) else BAD_EXCEPTION), _describe(e)
    if case.kind == "yaml":
        duplicate = _duplicate_yaml_key(case.data)
        if duplicate:
            return BAD_INPUT_ACCEPTED, f"loaded although the YAML repeats the key {duplicate!r}"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return _probe(robot)


def _duplicate_yaml_key(data):
    """The first key that a YAML mapping of ``data`` repeats, or None (the text has loaded already,
    so it is neither malformed nor a bomb)."""
    import yaml

    found = []

    class Strict(yaml.SafeLoader):
        def construct_mapping(self, node, deep=False):
            seen = set()
            for key_node, _ in node.value:
                key = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
                if key is not None and key in seen and not found:
                    found.append(key)
                seen.add(key)
            return super().construct_mapping(node, deep)

    try:
        yaml.load(data, Loader=Strict)
    except Exception:
        return None
    return found[0] if found else None


# ============================================================================ array cases
def run_call(case: Case):
    import kinedyn as kd

    spec, method, args, kwargs = case.call
    robot = make_robot(spec)
    fn = (lambda *a, **k: kd.simulate(robot, *a, **k)) if method == "simulate" else getattr(robot, method)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = fn(*args, **kwargs)
    except (ValueError, TypeError, MemoryError) as e:
        return CLEAN, _describe(e)
    except BaseException as e:
        return (PANIC if _is_panic(e) else BAD_EXCEPTION), _describe(e)
    problem = _input_problem(list(args) + [v for k, v in kwargs.items() if k != "out"])  # out= is written, not read
    if problem:
        return BAD_INPUT_ACCEPTED, f"{problem} input accepted; the result is{'' if nonfinite(out) else ' not'} finite"
    if method == "lock_joints":  # a Robot; its limits may be infinite by design
        return SUCCESS, f"a robot with {out.n} joints"
    if nonfinite(out):
        return NONFINITE, "finite input, non-finite result"
    return SUCCESS, "finite result"


# ============================================================================ self-test cases
def run_selftest(case: Case):
    """Cases that misbehave on purpose, to check the harness's own classification (tests/test_fuzz.py)."""
    what = case.data
    if what == "canary":  # what a loader that evaluates Python would do with the canary expression
        from .strategies import CANARY

        eval(CANARY)
        return CLEAN, "evaluated the canary"
    if what == "segfault":
        import ctypes

        ctypes.string_at(0)
    if what == "abort":
        os.abort()
    if what == "hang":
        time.sleep(3600)
    if what == "memory":
        return (
            run_file(Case(kind="yaml", seed="selftest", ops=(), data="name: x\n"), os.getcwd())
            if bytearray(8 << 30)
            else None
        )
    if what == "clean":
        return run_file(Case(kind="yaml", seed="selftest", ops=(), data="name: [1, 2]\n"), os.getcwd())
    raise ValueError(f"unknown self-test {what!r}")


def run_case(case: Case, folder: str, marker: str):
    """(outcome, detail) of one case; the code-execution canary overrides any other outcome."""
    start = time.perf_counter()
    if case.kind == "selftest":
        try:
            outcome, detail = run_selftest(case)
        except MemoryError as e:
            outcome, detail = MEMORY, _describe(e)
    else:
        if case.kind in ("mjcf", "mesh", "log", "viewer", "output"):
            from .surfaces import run_surface  # issue 25's surfaces

            outcome, detail = run_surface(case, folder)
        else:
            outcome, detail = run_file(case, folder) if case.kind != "arrays" else run_call(case)
    if case.valid and outcome == CLEAN:
        outcome, detail = VALID_REJECTED, f"a valid input was rejected: {detail}"
    if os.environ.pop(CANARY_ENV, None) is not None or os.path.exists(marker):
        detail = f"the canary ran (was: {outcome}: {detail})"
        outcome = CODE_EXEC
        if os.path.exists(marker):
            os.remove(marker)
    return {"index": case.index, "outcome": outcome, "detail": detail, "seconds": time.perf_counter() - start}


# ============================================================================ the protocol
def read_frame(stream):
    head = stream.read(8)
    if len(head) < 8:
        return None
    (size,) = struct.unpack("<Q", head)
    return pickle.loads(stream.read(size))


def write_frame(stream, obj) -> None:
    body = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(struct.pack("<Q", len(body)) + body)
    stream.flush()


def _exit_with_parent() -> None:
    """A daemon thread that ends the worker when the parent is gone (killed, or Ctrl-C), even in
    the middle of a hanging case. On Linux the kernel does it (PR_SET_PDEATHSIG), also while a case
    holds the GIL in a long C call; the thread is the fallback elsewhere."""
    import threading

    parent = os.getppid()
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, 9, 0, 0, 0)  # PR_SET_PDEATHSIG = 1, SIGKILL = 9
    except (OSError, AttributeError):
        pass

    def watch():
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(3)

    threading.Thread(target=watch, daemon=True).start()


def main() -> None:
    _exit_with_parent()
    proto_in = sys.stdin.buffer
    proto_out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # prints of the library go to stderr, never into the protocol
    faulthandler.enable()  # a crash leaves its Python traceback in the stderr file
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    import sympy  # noqa: F401
    import yaml  # noqa: F401

    import kinedyn  # noqa: F401  (imported before the limit: the import is not what is tested)

    memory = int(os.environ.get("KD_FUZZ_MEMORY", str(2 << 30)))
    if memory > 0:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    folder = os.getcwd()
    marker = os.environ[MARKER_ENV]
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 1000))
    write_frame(proto_out, {"ready": os.getpid()})
    while True:
        case = read_frame(proto_in)
        if case is None:
            return
        try:  # the stderr file holds only the current case's output
            os.ftruncate(2, 0)
            os.lseek(2, 0, os.SEEK_SET)
        except OSError:  # stderr is not a file (run by hand)
            pass
        write_frame(proto_out, run_case(case, folder, marker))


if __name__ == "__main__":
    main()
