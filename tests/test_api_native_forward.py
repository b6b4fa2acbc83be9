"""The thin call path of Robot's per-state methods (issue 30, "a thinner Python call"):

- a method declared ``@batched(..., native=True)`` is called through a generated wrapper that calls
  the native model's method of the same name itself; the method's own body (``__wrapped__``, which
  dask's chunks run) must give the same numbers, the same errors and honour ``out=``;
- ``pose`` and the kinematics methods leave q's conversion and checks to the native model: the
  messages naming the argument, its shape, a NaN and a frame stay those of the Python checks.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import kinedyn as kd

pytest.importorskip("kinedyn._core", reason="the native module is not built")

NATIVE = sorted(name for name, f in vars(kd.Robot).items() if getattr(f, "__kinedyn_native__", False) and callable(f))

GRIPPER = """<robot name="g">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0.1 0"/><mass value="0.5"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.02"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.1 0 0"/><mass value="0.3"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0 0.2 0"/><axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="j2" multiplier="-0.5" offset="0.1"/></joint>
</robot>"""


@pytest.fixture(scope="module", params=["ur5", "mimic"])
def robot(request):
    return kd.robots.ur5() if request.param == "ur5" else kd.Robot.from_urdf(GRIPPER)


def arguments(robot, method: str, batch: int | None, rng) -> dict:
    """Random states for every state parameter of ``method`` (q, qd, qdd, tau), one or a batch."""
    size = () if batch is None else (batch,)
    args = {}
    for name in inspect.signature(getattr(kd.Robot, method)).parameters:
        if name == "q":
            args[name] = robot.random_configuration(rng, size=batch)
        elif name in ("qd", "qdd", "tau"):
            args[name] = rng.uniform(-2, 2, size + (robot.n,))
    return args


def test_the_fast_path_covers_the_per_state_dynamics():
    assert {"inverse_dynamics", "mass_matrix", "forward_dynamics", "gravity_torque", "kinetic_energy"} <= set(NATIVE)


@pytest.mark.parametrize("batch", [None, 3])
@pytest.mark.parametrize("method", NATIVE)
def test_native_call_equals_the_method_body(robot, method, batch):
    rng = np.random.default_rng(7)
    args = arguments(robot, method, batch, rng)
    fast = getattr(robot, method)(**args)
    body = getattr(kd.Robot, method).__wrapped__(robot, **args)
    fast, body = (fast, body) if isinstance(fast, tuple) else ((fast,), (body,))
    assert len(fast) == len(body)
    for f, b in zip(fast, body):
        assert type(f) is type(b)
        np.testing.assert_array_equal(f, b)
    if "out" in inspect.signature(getattr(kd.Robot, method)).parameters:
        out = np.full_like(body[0], np.nan)
        assert getattr(robot, method)(**args, out=out) is out
        np.testing.assert_array_equal(out, body[0])


def test_errors_are_mapped_as_by_the_method_body():
    """A singular mass matrix names the joint through robot_error on both paths."""
    link = kd.Link("l1", "base", kd.Joint("j1", "revolute", axis=(0, 0, 1)), inertia=kd.Inertia(mass=0.0))
    robot = kd.Robot([link])
    q = np.zeros(1)
    for method, args in [
        ("forward_dynamics", (q, q, q)),
        ("mass_matrix_inverse", (q,)),
        ("forward_dynamics_derivatives", (q, q, q)),
    ]:
        with pytest.raises(RuntimeError) as fast:
            getattr(robot, method)(*args)
        with pytest.raises(RuntimeError) as body:
            getattr(kd.Robot, method).__wrapped__(robot, *args)
        assert type(fast.value) is type(body.value) and str(fast.value) == str(body.value)
        assert "j1" in str(fast.value)


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda r: r.pose(np.zeros(5)), ValueError, r"q must have shape \(6,\) or a batch \(N, 6\), got \(5,\)"),
        (lambda r: r.pose([0, 0, np.nan, 0, 0, 0]), ValueError, "q contains a non-finite value"),
        (lambda r: r.pose(np.zeros(6, complex)), TypeError, "q must be real numbers, got complex numbers"),
        (lambda r: r.pose([10**400] * 6), ValueError, "q holds an integer too large for float64"),
        (lambda r: r.pose(np.zeros(6), "nowhere"), ValueError, "unknown frame 'nowhere'"),
        (lambda r: r.jacobian(np.zeros(6, "U1")), TypeError, "q must be real numbers, got an array of dtype <U1"),
        (lambda r: r.jacobian(np.zeros((2, 7))), ValueError, r"q must have shape \(6,\) or a batch \(N, 6\)"),
        (lambda r: r.frame_velocity(np.zeros(6), [np.inf] * 6), ValueError, "qd contains a non-finite value"),
        (lambda r: r.forward_kinematics("abc"), TypeError, "q must be real numbers"),
    ],
)
def test_kinematics_checks_in_the_native_model_keep_their_messages(call, error, message):
    with pytest.raises(error, match=message):
        call(kd.robots.ur5())


def test_pose_is_the_frame_poses_entry():
    robot = kd.robots.ur5()
    q = robot.random_configuration(np.random.default_rng(3), size=4)
    frames = robot.frame_poses(q)
    for k, name in enumerate(robot.frame_names):
        np.testing.assert_array_equal(robot.pose(q, name), frames[:, k])
        np.testing.assert_array_equal(robot.pose(q[1], name), frames[1, k])
    np.testing.assert_array_equal(robot.pose(q), robot.pose(q, robot.tool))
    np.testing.assert_array_equal(robot.pose(q.tolist()), robot.pose(q))  # lists and Fortran order
    np.testing.assert_array_equal(robot.pose(np.asfortranarray(q)), robot.pose(q))
