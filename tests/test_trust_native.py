"""Trust at the native boundary (issue 11, sections 6, 7, 8 and the array calls of 11).

- 6: no Rust panic reaches Python: a panic is a RuntimeError naming the binding; a result that
  cannot be allocated is a MemoryError naming its bytes (also under an address-space limit).
- 7: batch calls work in a child made by fork after the parent used the batch pool; Robot and the
  result objects pickle and deep-copy, the native model rebuilt on the other side.
- 8: finite inputs with a non-finite result raise NonFiniteResultError naming the quantity (and
  the state of a batch); singular mass matrices say what is wrong.
- 11: complex input, bad integer settings, DLS with zero damping at a singularity, one f_ext
  for a batch, lock_joints with a sequence; and a hypothesis sweep of bad arrays over every public
  numeric method (only clean exceptions or finite results).
"""

from __future__ import annotations

import copy
import os
import pickle
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import kinedyn as kd
from kinedyn import _core

PACKAGE_PARENT = (
    Path(kd.__file__).resolve().parents[1]
)  # the kinedyn under test: the working tree's or an installed wheel's


def _run_script(code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Run `code` in a fresh interpreter that imports the kinedyn under test; a hang fails the
    test by the timeout instead of blocking the suite, and the script's whole process group (forked
    workers included, which a hang would otherwise leave behind) is killed then."""
    import signal

    env = dict(os.environ, PYTHONPATH=str(PACKAGE_PARENT), RUST_BACKTRACE="0")
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
    )
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail(f"the script did not finish in {timeout} s (a hang):\n{textwrap.dedent(code)}")
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


@pytest.fixture(scope="module")
def puma():
    return kd.robots.puma560()


@pytest.fixture(scope="module")
def ur5():
    return kd.robots.ur5()


# ------------------------------------------------------------------ 6. no panic reaches Python
@pytest.mark.parametrize("in_worker", [False, True])
def test_a_panic_is_a_runtime_error_naming_the_binding(in_worker):
    try:
        _core._debug_panic("deliberate test panic", in_worker)
    except Exception as e:  # noqa: BLE001 - the point: `except Exception` catches it
        assert type(e) is RuntimeError
        assert "_debug_panic" in str(e) and "deliberate test panic" in str(e)
    else:
        pytest.fail("_debug_panic returned")
    # the module keeps working after a caught panic (no poisoned state)
    assert kd.robots.planar_2r().mass_matrix(np.zeros((3, 2))).shape == (3, 2, 2)


def test_an_impossible_simulation_is_a_memory_error_at_once(puma):
    # dt = 1e-12 over 1 s: 1e12 samples of 6 joints, 4 arrays: 175 TiB
    t0 = time.perf_counter()
    with pytest.raises((MemoryError, ValueError)) as info:
        kd.simulate(puma, (0, 1), np.zeros(12), dt=1e-12)
    assert time.perf_counter() - t0 < 10.0
    assert "bytes" in str(info.value)


def test_an_impossible_batch_result_is_a_memory_error(puma):
    # a Christoffel batch (N, 6, 6, 6) of 2**55 states from a broadcast q: neither the copy of q
    # (1.7e18 bytes) nor the result (6.2e19 bytes) can be allocated: MemoryError, not an abort
    q = np.lib.stride_tricks.as_strided(np.zeros(6), shape=(2**55, 6), strides=(0, 8))
    with pytest.raises(MemoryError, match="bytes"):
        puma.christoffel(q)


def test_batches_under_an_address_space_limit_raise_memory_error():
    # every batch method under `ulimit -v`: MemoryError, never PanicException or an abort
    result = _run_script(
        """
        import resource, numpy as np, kinedyn as kd
        robot = kd.robots.puma560()
        N = 1_000_000
        q = np.random.default_rng(0).uniform(-1, 1, (N, 6))
        targets = np.random.default_rng(0).uniform(-0.3, 0.3, (4 * N, 3))  # batch IK: 384 MB of poses
        robot.mass_matrix(q[:1000]); robot.inverse_kinematics(robot.pose(q[:8]), method="numeric")  # pools started
        def vm():
            for line in open("/proc/self/status"):
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
        limit = vm() + 150 * 2**20
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        calls = {
            "mass_matrix": lambda: robot.mass_matrix(q),
            "christoffel": lambda: robot.christoffel(q),
            "regressor": lambda: robot.regressor(q, q, q),
            "inverse_dynamics_derivatives": lambda: robot.inverse_dynamics_derivatives(q, q, q),
            "forward_kinematics": lambda: robot.forward_kinematics(q),
            "jacobian": lambda: robot.jacobian(q),
            "simulate": lambda: kd.simulate(robot, (0, 10), np.zeros(12), dt=1e-5, method="rk4"),
            "inverse_kinematics": lambda: robot.inverse_kinematics(targets, method="numeric"),
        }
        for name, call in calls.items():
            try:
                call()
            except MemoryError as e:
                print(name, "MemoryError", str(e)[:60])
            else:
                print(name, "no error")
        print("alive")
        """
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert "PanicException" not in result.stdout + result.stderr
    lines = result.stdout.splitlines()
    assert lines[-1] == "alive"
    for name in (
        "mass_matrix",
        "christoffel",
        "regressor",
        "inverse_dynamics_derivatives",
        "forward_kinematics",
        "jacobian",
        "simulate",
        "inverse_kinematics",
    ):
        assert f"{name} MemoryError" in result.stdout, result.stdout


# ------------------------------------------------------------------ 7. fork-safe and picklable
def test_batches_in_forked_children_after_the_parent_used_the_pool():
    result = _run_script(
        """
        import multiprocessing as mp, os, numpy as np, kinedyn as kd
        robot = kd.robots.puma560()
        Q = np.random.default_rng(1).uniform(-1, 1, (500, 6))
        expected = robot.mass_matrix(Q).sum()
        robot.inverse_kinematics(robot.pose(Q[:16]), method="numeric")  # the parent's pool runs IK too

        def work(i):
            ik = robot.inverse_kinematics(robot.pose(Q[:16]), method="numeric")
            return float(robot.mass_matrix(Q).sum()), float(ik.success_rate)

        with mp.get_context("fork").Pool(2) as pool:
            for total, rate in pool.map(work, range(4)):
                assert abs(total - expected) < 1e-9 * abs(expected) and rate > 0.5, (total, rate)
        pid = os.fork()
        if pid == 0:  # a bare os.fork child: its next batch call
            ok = abs(robot.mass_matrix(Q).sum() - expected) < 1e-9 * abs(expected)
            os._exit(0 if ok else 3)
        _, status = os.waitpid(pid, 0)
        assert os.waitstatus_to_exitcode(status) == 0, status
        print("forked ok")
        """,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert "forked ok" in result.stdout


def _spawn_worker(robot_and_q):
    robot, q = robot_and_q
    return robot.mass_matrix(q), robot.inverse_dynamics(q, q, q)


def test_a_robot_goes_to_a_spawn_pool_worker(ur5):
    import multiprocessing as mp

    q = np.random.default_rng(2).uniform(-1, 1, (64, ur5.n))
    ur5.mass_matrix(q)  # native model built before pickling
    env_path = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = str(PACKAGE_PARENT) + (os.pathsep + env_path if env_path else "")
    try:
        with mp.get_context("spawn").Pool(1) as pool:
            M, tau = pool.apply_async(_spawn_worker, ((ur5, q),)).get(timeout=120)
    finally:
        if env_path is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = env_path
    np.testing.assert_array_equal(M, ur5.mass_matrix(q))
    np.testing.assert_array_equal(tau, ur5.inverse_dynamics(q, q, q))


@pytest.mark.parametrize(
    "clone", [lambda r: pickle.loads(pickle.dumps(r)), copy.deepcopy, copy.copy], ids=["pickle", "deepcopy", "copy"]
)
def test_robot_round_trips_after_native_use(puma, clone):
    q = puma.random_configuration(rng=3, size=5)
    M = puma.mass_matrix(q)
    ik = puma.inverse_kinematics(puma.pose(q[0]))  # builds the IK cache too
    other = clone(puma)
    assert other is not puma and other.joint_names == puma.joint_names
    np.testing.assert_array_equal(other.mass_matrix(q), M)
    np.testing.assert_allclose(other.inverse_kinematics(puma.pose(q[0])).solutions, ik.solutions)
    np.testing.assert_array_equal(other.forward_kinematics(q), puma.forward_kinematics(q))


def test_a_symbolic_robot_pickles():
    import sympy as sp

    l1, l2 = sp.symbols("l1 l2", positive=True)
    robot = kd.Robot.from_dh([(0, 0, l1, 0), (0, 0, l2, 0)])
    back = pickle.loads(pickle.dumps(robot))
    assert back.symbols == robot.symbols
    np.testing.assert_allclose(
        back.subs({"l1": 1.0, "l2": 2.0}).pose([0.3, 0.4]), robot.subs({"l1": 1.0, "l2": 2.0}).pose([0.3, 0.4])
    )


def test_results_pickle(puma):
    q = puma.random_configuration(rng=4, size=6)
    results = [
        puma.inverse_kinematics(puma.pose(q[0])),
        puma.inverse_kinematics(puma.pose(q[0]), method="numeric"),
        puma.inverse_kinematics(puma.pose(q), method="numeric"),
        kd.simulate(puma, (0, 0.02), np.zeros(12), dt=1e-3),
    ]
    for r in results:
        back = pickle.loads(pickle.dumps(r))
        assert type(back) is type(r)
        for name in ("solutions", "q", "position_error", "success", "t", "qd", "tau"):
            if hasattr(r, name):
                np.testing.assert_array_equal(getattr(back, name), getattr(r, name))
    traj = pickle.loads(pickle.dumps(results[-1]))
    np.testing.assert_array_equal(traj.system.mass_matrix(q), puma.mass_matrix(q))


# ------------------------------------------------------------------ 8. no silent non-finite result
def test_finite_inputs_with_overflowing_results_raise(puma):
    q = np.zeros(6)
    with pytest.raises(kd.NonFiniteResultError, match=r"inverse_dynamics: tau\[\d\]") as info:
        puma.inverse_dynamics(q, 1e154 * np.ones(6), q)
    assert isinstance(info.value, ValueError) and isinstance(info.value, FloatingPointError)
    with pytest.raises(kd.NonFiniteResultError, match="kinetic_energy: K is"):
        puma.kinetic_energy(q, 1e200 * np.ones(6))
    # in a batch, the state is named
    qd = np.zeros((10, 6))
    qd[7] = 1e200
    with pytest.raises(kd.NonFiniteResultError, match="state 7 of the batch"):
        puma.bias_torque(np.zeros((10, 6)), qd)
    with pytest.raises(kd.NonFiniteResultError, match="tool_velocity"):
        kd.kinematics.tool_velocity(puma, q, np.full(6, 1e308))
    viscous = kd.Robot.from_dh(
        [{"theta": 0, "d": 0, "a": 1, "alpha": 0, "viscous": 10.0, "inertia": kd.Inertia.rod(1.0, 1.0)}]
    )
    with pytest.raises(kd.NonFiniteResultError, match="friction_torque"):
        viscous.friction_torque([1.7e308])


def _two_link(first, second):
    """planar 2R (links of length 1, no gravity) with the given link inertias."""
    return kd.Robot.from_dh(
        [
            {"theta": 0, "d": 0, "a": 1, "alpha": 0, "inertia": first},
            {"theta": 0, "d": 0, "a": 1, "alpha": 0, "inertia": second},
        ],
        gravity=(0, 0, 0),
    )


def test_bodies_of_very_different_sizes_invert_exactly():
    # a 1e20 kg first link next to a 1 kg second link: M is well conditioned in its L^T D L factors
    # (the old test of each pivot against the largest diagonal entry called link 2 "massless")
    robot = _two_link(kd.Inertia.rod(1e20, 1.0), kd.Inertia.rod(1.0, 1.0))
    q = [0.0, 0.5]
    Minv = robot.mass_matrix_inverse(q)
    np.testing.assert_allclose(Minv @ robot.mass_matrix(q), np.eye(2), atol=1e-12)
    tau = np.array([1e20, 1.0])
    np.testing.assert_allclose(robot.forward_dynamics(q, [0, 0], tau), Minv @ tau, rtol=1e-9)


def test_a_numerically_singular_mass_matrix_says_what_is_wrong():
    # a 1e20 kg point mass at the tip of link 2 with the arm stretched: M's determinant is lost in
    # float64 (M = 1e20 [[4, 2], [2, 1]] + O(1)); the message says so instead of "massless"
    robot = _two_link(kd.Inertia.rod(1.0, 1.0), kd.Inertia.point_mass(1e20))
    with pytest.raises(RuntimeError) as info:
        robot.mass_matrix_inverse([0.0, 0.0])
    message = str(info.value)
    assert "massless" not in message
    assert "numerically singular" in message and "differ by more than float64 can resolve" in message
    assert "joint 'q1' (moving body 'link1')" in message and "joint 0" not in message
    with pytest.raises(RuntimeError, match="negligible next to the rest") as info:
        robot.forward_dynamics([0.0, 0.0], [0, 0], [1, 0])
    # a subtree with no inertia about its axis is still called that
    empty = kd.Robot.from_dh([(0, 0, 1, 0), (0, 0, 1, 0)])
    with pytest.raises(RuntimeError, match="no inertia about the joint's axis"):
        empty.mass_matrix_inverse([0.0, 0.5])


def test_finite_results_are_not_flagged(ur5):
    q = ur5.random_configuration(rng=5, size=100)
    assert np.isfinite(ur5.inverse_dynamics(q, q, q)).all()
    assert np.isfinite(ur5.christoffel(q)).all()


# ------------------------------------------------------------------ 11. array calls
COMPLEX = np.zeros(6) + 1j


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda r: r.mass_matrix(COMPLEX), "q"),
        (lambda r: r.inverse_dynamics(np.zeros(6), COMPLEX, np.zeros(6)), "qd"),
        (lambda r: r.forward_kinematics(list(COMPLEX)), "q"),
        (lambda r: r.jacobian(COMPLEX), "q"),
        (lambda r: r.frame_velocity(np.zeros(6), COMPLEX), "qd"),
        (lambda r: r.inverse_dynamics(np.zeros(6), np.zeros(6), np.zeros(6), f_ext=np.zeros((6, 6)) + 0j), "f_ext"),
        (lambda r: r.friction_torque(COMPLEX), "qd"),
        (lambda r: r.inverse_kinematics(np.eye(4) + 0j), "target"),
        (lambda r: kd.kinematics.tool_velocity(r, np.zeros(6), COMPLEX), "qd"),
        (lambda r: r.mass_matrix(np.array(["1"] * 6)), "q"),
    ],
)
def test_complex_or_text_input_is_refused(puma, call, name):
    with pytest.raises((TypeError, ValueError), match=rf"\b{name}\b.*(real|complex|dtype)"):
        call(puma)


def test_dls_with_zero_damping_at_a_singularity_is_the_minimum_norm_answer(puma):
    q = np.zeros(6)  # the Puma's zero pose is singular (wrist axes 4 and 6 aligned)
    J = puma.jacobian(q)
    assert np.linalg.matrix_rank(J) < 6
    v = np.array([0.1, -0.2, 0.3, 0.2, 0.1, -0.1])
    qd = kd.kinematics.joint_velocities(puma, q, v, method="dls", damping=0.0)
    expected = np.linalg.lstsq(J, v, rcond=1e-12)[0]  # minimum-norm least squares
    np.testing.assert_allclose(qd, expected, atol=1e-9)
    np.testing.assert_allclose(kd.kinematics.joint_velocities(puma, q, v, method="pinv"), expected, atol=1e-9)
    # damping > 0 still damps, and a batch agrees with single calls
    qs = np.stack([q, puma.random_configuration(rng=6)])
    batch = kd.kinematics.joint_velocities(puma, qs, v, method="dls", damping=0.05)
    for k in range(2):
        Jk = puma.jacobian(qs[k])
        np.testing.assert_allclose(batch[k], Jk.T @ np.linalg.solve(Jk @ Jk.T + 0.05**2 * np.eye(6), v), atol=1e-9)


@pytest.mark.parametrize(
    "name, value",
    [
        ("max_iterations", 2**64),
        ("max_iterations", -1),
        ("max_iterations", 2.5),
        ("restarts", 2**40),
        ("seed", -3),
        ("seed", 2**64),
        ("tolerance", float("nan")),
        ("tolerance", 1j),
    ],
)
def test_ik_settings_are_checked_by_name(puma, name, value):
    with pytest.raises(ValueError, match=name):
        puma.inverse_kinematics(puma.pose(np.full(6, 0.3)), method="numeric", **{name: value})


def test_one_f_ext_for_a_batch_of_states(puma, ur5):
    for robot in (puma, ur5):  # DH (link frames offset from the body frames) and URDF
        rng = np.random.default_rng(7)
        q, qd, qdd = (rng.uniform(-1, 1, (4, robot.n)) for _ in range(3))
        f = rng.uniform(-5, 5, (robot.n, 6))
        batch = robot.inverse_dynamics(q, qd, qdd, f_ext=f)
        one_by_one = np.stack([robot.inverse_dynamics(q[k], qd[k], qdd[k], f_ext=f) for k in range(4)])
        np.testing.assert_allclose(batch, one_by_one, atol=1e-12)
        np.testing.assert_allclose(
            robot.forward_dynamics(q, qd, qdd, f_ext=f),
            np.stack([robot.forward_dynamics(q[k], qd[k], qdd[k], f_ext=f) for k in range(4)]),
            atol=1e-10,
        )
        dq = robot.inverse_dynamics_derivatives(q, qd, qdd, f_ext=f)[0]
        np.testing.assert_allclose(
            dq,
            np.stack([robot.inverse_dynamics_derivatives(q[k], qd[k], qdd[k], f_ext=f)[0] for k in range(4)]),
            atol=1e-10,
        )
        with pytest.raises(ValueError, match=rf"f_ext must have shape \({robot.n}, 6\)"):
            robot.inverse_dynamics(q, qd, qdd, f_ext=np.zeros((robot.n, 5)))


def test_lock_joints_takes_any_sequence_of_names_or_indices(puma):
    expected = puma.lock_joints({"q5": 0.0, "q6": 0.0})
    q = np.array([0.1, 0.2, 0.3, 0.4])
    for joints in (["q5", "q6"], ("q5", 5), [4, 5], np.array([4, 5]), {"q6", "q5"}, (j for j in ["q5", "q6"])):
        locked = puma.lock_joints(joints)
        assert locked.joint_names == ["q1", "q2", "q3", "q4"]
        np.testing.assert_allclose(locked.mass_matrix(q), expected.mass_matrix(q))
    at = np.array([0, 0, 0, 0, 0.7, -0.2])
    np.testing.assert_allclose(puma.lock_joints([4, 5], at=at).pose(q), puma.pose(np.r_[q, 0.7, -0.2]))
    np.testing.assert_allclose(puma.lock_joints({4: 0.7, "q6": -0.2}).pose(q), puma.pose(np.r_[q, 0.7, -0.2]))
    with pytest.raises(ValueError, match=r"unknown joints \['j1'\]"):
        puma.lock_joints(["j1"])
    with pytest.raises(ValueError, match="out of range"):
        puma.lock_joints([6])
    with pytest.raises(TypeError, match="name or an index"):
        puma.lock_joints([1.5])


# ------------------------------------------------------------------ hypothesis: every numeric method
_N = 6
_GOOD = np.linspace(-0.4, 0.5, _N)

_ARGS = {  # method: the per-state shapes of its array arguments
    "forward_kinematics": [(_N,)],
    "pose": [(_N,)],
    "jacobian": [(_N,)],
    "frame_velocity": [(_N,), (_N,)],
    "jacobian_dot_qd": [(_N,), (_N,)],
    "inverse_dynamics": [(_N,), (_N,), (_N,)],
    "mass_matrix": [(_N,)],
    "mass_matrix_inverse": [(_N,)],
    "forward_dynamics": [(_N,), (_N,), (_N,)],
    "inverse_dynamics_derivatives": [(_N,), (_N,), (_N,)],
    "forward_dynamics_derivatives": [(_N,), (_N,), (_N,)],
    "coriolis_matrix": [(_N,), (_N,)],
    "christoffel": [(_N,)],
    "gravity_torque": [(_N,)],
    "bias_torque": [(_N,), (_N,)],
    "kinetic_energy": [(_N,), (_N,)],
    "potential_energy": [(_N,)],
    "center_of_mass": [(_N,)],
    "momentum": [(_N,), (_N,)],
    "regressor": [(_N,), (_N,), (_N,)],
    "friction_torque": [(_N,)],
}
_FUNCTIONS = {  # kinedyn.kinematics / ik functions: (callable(robot, *arrays), shapes)
    "tool_velocity": (lambda r, q, v: kd.kinematics.tool_velocity(r, q, v), [(_N,), (_N,)]),
    "joint_torques": (lambda r, q, w: kd.kinematics.joint_torques(r, q, w), [(_N,), (6,)]),
    "joint_velocities_dls": (
        lambda r, q, v: kd.kinematics.joint_velocities(r, q, v, method="dls", damping=0.0),
        [(_N,), (6,)],
    ),
    "joint_velocities_pinv": (lambda r, q, v: kd.kinematics.joint_velocities(r, q, v, method="pinv"), [(_N,), (6,)]),
    "manipulability": (lambda r, q: kd.kinematics.manipulability(r, q), [(_N,)]),
    "inverse_kinematics": (
        lambda r, t, q0: r.inverse_kinematics(t, q0=q0, method="numeric", restarts=1, max_iterations=5),
        [(3,), (_N,)],
    ),
    "inverse_dynamics_f_ext": (lambda r, q, f: r.inverse_dynamics(q, q, q, f_ext=f), [(_N,), (_N, 6)]),
}

_VALUES = st.sampled_from([0.0, 0.3, -1.0, 1e3, 1e150, -1e200, 1e300, 1.7e308, np.nan, np.inf, -np.inf, 5e-324])


@st.composite
def _bad_array(draw, shape):
    """An argument near `shape`: right or wrong shape, batch or not, odd dtype, extreme values."""
    kind = draw(st.sampled_from(["good", "batch", "shape", "dtype", "values", "scalar", "list", "empty_batch"]))
    if kind == "scalar":
        return draw(st.sampled_from([0.5, 1j, "x", None, True]))
    if kind == "shape":
        dims = draw(st.lists(st.integers(0, 7), min_size=0, max_size=3))
        return np.full(dims, 0.2)
    if kind == "empty_batch":
        return np.zeros((0, *shape))
    base = np.resize(_GOOD, shape).astype(float)
    if kind == "batch":
        base = np.stack([base] * draw(st.integers(1, 3)))
    if kind in ("values", "batch"):
        flat = base.reshape(-1)
        for i in draw(st.lists(st.integers(0, max(flat.size - 1, 0)), max_size=3)):
            if flat.size:
                flat[i] = draw(_VALUES)
    if kind == "dtype":
        dtype = draw(st.sampled_from([np.float32, np.int64, np.complex128, np.bool_, object, "U8", np.float16]))
        return base.astype(dtype)
    if kind == "list":
        return base.tolist()
    return base


def _outcome(call) -> str:
    """Run `call` and classify what it did: "clean error" (ValueError, TypeError, MemoryError, or
    the documented singular-mass-matrix RuntimeError), "finite" (numbers, all finite), or a defect:
    "non-finite result", "unclean <type>: <message>" (any other exception, a panic included)."""
    try:
        out = call()
    except (ValueError, TypeError, MemoryError):
        return "clean error"
    except RuntimeError as e:  # only the documented singular-mass-matrix error
        if "not positive definite" in str(e) or "articulated inertia" in str(e):
            return "clean error"
        return f"unclean RuntimeError: {e}"
    except BaseException as e:  # noqa: BLE001 - pyo3's PanicException is a BaseException
        if isinstance(e, (KeyboardInterrupt, SystemExit)):
            raise
        return f"unclean {type(e).__name__}: {e}"
    values = out.solutions if hasattr(out, "solutions") else getattr(out, "q", out)
    for v in values if isinstance(values, tuple) else (values,):
        a = np.asarray(v)
        # (numeric IK reports failure with its best iterate; it must still be finite)
        if a.dtype.kind in "fc" and a.size and not np.isfinite(a).all():
            return "non-finite result"
    return "finite"


def _check_outcome(call):
    """A clean exception (ValueError, TypeError, MemoryError) or finite numbers."""
    outcome = _outcome(call)
    assert outcome in ("clean error", "finite"), outcome


def fuzz_case(robot, data, name):
    """One generated call of method/function `name` with bad arrays drawn from `data`: its outcome
    (see `_outcome`). Shared by the test below and benches/fuzz_arrays.py (thousands of cases)."""
    if name in _ARGS:
        args = [data.draw(_bad_array(s), label=f"arg{i}") for i, s in enumerate(_ARGS[name])]
        return _outcome(lambda: getattr(robot, name)(*args))
    fn, shapes = _FUNCTIONS[name]
    args = [data.draw(_bad_array(s), label=f"arg{i}") for i, s in enumerate(shapes)]
    return _outcome(lambda: fn(robot, *args))


FUZZ_NAMES = sorted(_ARGS) + sorted(_FUNCTIONS)


@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
)
@given(data=st.data(), name=st.sampled_from(FUZZ_NAMES))
def test_bad_arrays_give_clean_errors_or_finite_results(puma, data, name):
    outcome = fuzz_case(puma, data, name)
    assert outcome in ("clean error", "finite"), outcome


def test_a_simulation_longer_than_float64_can_count_is_a_value_error(puma):
    with pytest.raises(ValueError, match=r"more than 2\*\*53"):
        kd.simulate(puma, (0, 1e300), np.zeros(12), dt=0.01)


@pytest.mark.parametrize("name", ["stanford", "cartesian_2p", "panda"])
def test_a_factorisation_that_overflows_is_a_non_finite_result_error(name):
    if name == "panda":  # finite M of 1e306 (the fingers at 1e154 m) beside a finger's 1.5e-2
        from reference import PANDA, erd

        robot = kd.Robot.from_urdf(
            erd(*PANDA), mimic="independent"
        )  # the native factorisation (test_mimic.py: reduced)
    else:
        robot = kd.robots.get(name)
    q = np.full(robot.n, 1e154)  # finite, but prismatic offsets of 1e154 m square to more than float64 holds
    calls = [
        lambda: robot.forward_dynamics(q, np.zeros(robot.n), np.zeros(robot.n))
    ]  # the ABA's spatial inertias overflow
    if name != "cartesian_2p":  # M overflows, or is too large to factor (the Cartesian arm's M does not depend on q)
        calls.append(lambda: robot.mass_matrix_inverse(q))
    for call in calls:
        with pytest.raises(kd.NonFiniteResultError, match="too large for float64"):
            call()


def test_a_simulation_whose_state_overflows_float64_is_a_value_error(puma):
    from kinedyn.simulate import SimulationError, SimulationOverflowError

    robot = kd.robots.stanford()  # prismatic: its inertias at 1e154 m overflow
    with pytest.raises(SimulationOverflowError, match="too large for float64") as info:
        kd.simulate(robot, 0.02, np.concatenate([np.full(6, 1e154), np.zeros(6)]), method="rk4")
    assert isinstance(info.value, (ValueError, kd.NonFiniteResultError, SimulationError))
    with pytest.raises(ValueError, match="x0 holds an integer too large for float64"):
        kd.simulate(robot, 0.02, 10**400)


def test_an_ik_target_beyond_any_reach_is_a_value_error(ur5):
    for target in (np.full(3, -1e154), np.full((2, 3), 1e200)):
        with pytest.raises(ValueError, match="beyond 1e\\+100 m"):
            ur5.inverse_kinematics(target, method="numeric")
    T = np.eye(4)
    T[:3, 3] = 1e150
    with pytest.raises(ValueError, match="target position is 1e\\+150 m from the base"):
        ur5.inverse_kinematics(T[None], method="numeric")


def test_a_step_longer_than_the_span_is_one_step_of_the_span():
    robot = kd.robots.planar_2r()
    x0 = np.array([0.3, -0.2, 0.0, 0.0])
    once = kd.simulate(robot, 0.02, x0, dt=1e300, method="rk4")
    reference = kd.simulate(robot, 0.02, x0, dt=0.02, method="rk4")
    np.testing.assert_array_equal(once.q, reference.q)
    assert once.t[-1] == pytest.approx(0.02)
