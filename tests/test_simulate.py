"""kinedyn.simulate: energy behaviour of the integrators, batches, controllers, constrained systems,
bad input and blow-ups, exports. Every tolerance below is an accuracy bound, never a timing."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.simulate import (
    PD,
    ComputedTorque,
    Cubic,
    Fourier,
    MechanicalSystem,
    NonFiniteTorqueError,
    PDGravity,
    Quintic,
    SimulationError,
    Trajectory,
)

pytest.importorskip("kinedyn._core", reason="the native module is not built")

X0_PUMA = np.r_[0.1, 0.5, -0.3, 0.2, 0.4, 0.1, 0.5, -0.3, 0.2, 1.0, -0.5, 0.8]


@pytest.fixture(scope="module")
def puma():
    return kd.robots.puma560(friction=False)


def rel_drift(traj):
    H = traj.H
    return float(np.abs(H - H[0]).max() / abs(H[0]))


# ------------------------------------------------------------------ energy
def test_rk4_conserves_energy_on_the_puma_for_5_s(puma):
    """Issue 6 acceptance: RK4 at 1 ms, 5 s, no friction: relative drift < 1e-6."""
    traj = kd.simulate(puma, 5.0, X0_PUMA, method="rk4", dt=1e-3)
    assert traj.q.shape == (5001, 6) and traj.t[-1] == pytest.approx(5.0)
    assert traj.info["native"]
    assert rel_drift(traj) < 1e-6
    # the same run with explicit Euler drifts visibly: the check can fail
    euler = kd.simulate(puma, 5.0, X0_PUMA, method="euler", dt=1e-3)
    assert rel_drift(euler) > 1e3 * rel_drift(traj)


def test_semi_implicit_energy_error_stays_bounded(puma):
    """Symplectic Euler: the energy error oscillates at O(dt) without growing (its maximum over the
    second half of the run is not larger than over the first), unlike explicit Euler's."""
    semi = kd.simulate(puma, 6.0, X0_PUMA, method="semi_implicit", dt=1e-3)
    err = np.abs(semi.H - semi.H[0]) / abs(semi.H[0])
    half = len(err) // 2
    assert err.max() < 2e-2
    assert err[half:].max() < 1.5 * err[:half].max()
    euler = kd.simulate(puma, 6.0, X0_PUMA, method="euler", dt=1e-3)
    e2 = np.abs(euler.H - euler.H[0]) / abs(euler.H[0])
    assert e2[half:].max() > 1.5 * e2[:half].max()  # explicit Euler's grows


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_adaptive_meets_its_tolerance(method):
    robot = kd.robots.planar_2r()
    x0 = np.r_[0.3, -0.7, 1.0, 3.0]
    reference = kd.simulate(robot, 2.0, x0, method="rk4", dt=1e-4, record_every=100)
    errors = []
    for rtol in (1e-6, 1e-9):
        traj = kd.simulate(robot, 2.0, x0, method=method, dt=1e-2, rtol=rtol, atol=rtol * 1e-2)
        assert traj.t.shape == reference.t.shape
        err = np.abs(traj.q - reference.q).max()
        scale = np.abs(reference.q).max()
        errors.append(err)
        # global error within a modest multiple of the requested local tolerance
        assert err < 100 * rtol * scale, (rtol, err)
    assert errors[1] < errors[0] / 10


def test_rk4_and_adaptive_agree_with_a_controller(puma):
    ctl = PDGravity(puma, 50.0, 10.0, np.zeros(6))
    a = kd.simulate(puma, 1.0, X0_PUMA, controller=ctl, dt=1e-3, record_every=10)
    b = kd.simulate(puma, 1.0, X0_PUMA, controller=ctl, method="dop853", dt=1e-2, rtol=1e-10, atol=1e-12)
    assert np.abs(a.q - b.q).max() < 1e-8


# ------------------------------------------------------------------ batches
def test_batch_equals_one_by_one(puma):
    rng = np.random.default_rng(1)
    X = np.column_stack([puma.random_configuration(rng, size=5), rng.normal(size=(5, 6))])
    tau = rng.normal(size=(301, 6)) * 5.0
    batch = kd.simulate(puma, 0.3, X, u=tau, dt=1e-3)
    assert batch.batch == 5 and batch.q.shape == (5, 301, 6)
    for i in range(5):
        one = kd.simulate(puma, 0.3, X[i], u=tau, dt=1e-3)
        np.testing.assert_array_equal(batch.q[i], one.q)
        np.testing.assert_array_equal(batch.qd[i], one.qd)
        np.testing.assert_array_equal(batch[i].tau, one.tau)
    # with a controller (the callback path) too
    ctl = PD(20.0, 5.0, np.zeros(6))
    b2 = kd.simulate(puma, 0.1, X[:2], controller=ctl)
    for i in range(2):
        np.testing.assert_allclose(b2.q[i], kd.simulate(puma, 0.1, X[i], controller=ctl).q, rtol=0, atol=0)


def test_sampled_torque_hold_and_linear_and_callable_agree():
    robot = kd.robots.planar_2r()
    x0 = np.r_[0.3, -0.7, 0.0, 0.0]
    dt, T = 1e-3, 0.5
    t = np.arange(501) * dt
    u_fn = lambda t, q, qd: np.array([np.sin(3 * t), 0.5 * np.cos(2 * t)])  # noqa: E731
    samples = np.column_stack([np.sin(3 * t), 0.5 * np.cos(2 * t)])
    linear = kd.simulate(robot, T, x0, u=samples, dt=dt)  # 501 samples: interpolated
    held = kd.simulate(robot, T, x0, u=samples[:-1], dt=dt)  # 500 samples: held per step
    exact = kd.simulate(robot, T, x0, u=u_fn, dt=dt)
    assert np.abs(linear.q - exact.q).max() < 1e-7
    assert np.abs(held.q - exact.q).max() > 10 * np.abs(linear.q - exact.q).max()
    np.testing.assert_allclose(exact.tau, samples, atol=1e-15)
    # constant torque == sampled constant
    c1 = kd.simulate(robot, T, x0, u=[1.0, -2.0], dt=dt)
    c2 = kd.simulate(robot, T, x0, u=np.tile([1.0, -2.0], (500, 1)), dt=dt)
    np.testing.assert_array_equal(c1.q, c2.q)


def test_record_every_keeps_the_same_samples(puma):
    full = kd.simulate(puma, 0.2, X0_PUMA, dt=1e-3)
    thin = kd.simulate(puma, 0.2, X0_PUMA, dt=1e-3, record_every=7)
    ks = list(range(0, 201, 7)) + [200]
    np.testing.assert_array_equal(thin.t, full.t[ks])
    np.testing.assert_array_equal(thin.q, full.q[ks])


def test_progress_bar_chunks_give_identical_samples(puma):
    one = kd.simulate(puma, 0.5, X0_PUMA, record_every=3, progress=False)
    chunked = kd.simulate(puma, 0.5, X0_PUMA, record_every=3, progress=True)
    np.testing.assert_array_equal(one.t, chunked.t)
    np.testing.assert_array_equal(one.q, chunked.q)
    np.testing.assert_array_equal(one.qdd, chunked.qdd)


# ------------------------------------------------------------------ controllers
def test_computed_torque_tracks_a_quintic_on_an_exact_model(puma):
    q0 = np.zeros(6)
    q1 = np.array([0.5, -0.4, 0.3, 0.8, -0.6, 1.0])
    ref = Quintic(q0, q1, T=2.0)
    ctl = ComputedTorque(puma, 100.0, 20.0, ref)
    traj = kd.simulate(puma, 2.5, np.r_[q0, np.zeros(6)], controller=ctl, dt=1e-3)
    qr, qdr, _ = ref(traj.t)
    assert np.abs(traj.q - qr).max() < 1e-8
    assert np.abs(traj.qd - qdr).max() < 1e-7
    # a model with 10 % heavier links does not track to that precision (the check can fail)
    wrong = kd.robots.puma560(friction=False, masses=[1.1 * m for m in kd.robots.industrial.PUMA560_MASSES])
    traj2 = kd.simulate(
        puma, 2.5, np.r_[q0, np.zeros(6)], controller=ComputedTorque(puma, 100.0, 20.0, ref, model=wrong), dt=1e-3
    )
    assert np.abs(traj2.q - qr).max() > 1e-6


def test_pd_gravity_compensation_converges_and_plain_pd_does_not(puma):
    goal = np.array([0.3, -0.5, 0.4, 0.2, 0.3, -0.2])
    x0 = np.r_[np.zeros(6), np.zeros(6)]
    traj = kd.simulate(puma, 6.0, x0, controller=PDGravity(puma, 100.0, 20.0, goal), dt=1e-3, record_every=10)
    assert np.abs(traj.q[-1] - goal).max() < 1e-4
    assert np.abs(traj.qd[-1]).max() < 1e-3
    # Lyapunov function V = K + e^T Kp e / 2 never increases (Spong's argument; dV/dt = -qd^T Kd qd)
    e = goal - traj.q
    V = traj.K + 0.5 * 100.0 * np.einsum("si,si->s", e, e)
    assert np.diff(V).max() < 1e-9 * V[0]
    # plain PD: a steady-state error under gravity
    pd_traj = kd.simulate(puma, 6.0, x0, controller=PD(100.0, 20.0, goal), dt=1e-3, record_every=10)
    assert np.abs(pd_traj.q[-1] - goal).max() > 1e-2


def test_references_derivatives_match_finite_differences():
    h = 1e-6
    for ref in (
        Cubic([0, 1], [2, -1], 1.5, t0=0.2),
        Quintic([0, 1], [2, -1], 1.5),
        Fourier.random(3, harmonics=4, seed=2),
    ):
        t = np.linspace(0.05, 1.5, 40)
        q, qd, qdd = ref(t)
        qp, qdp, _ = ref(t + h)
        qm, qdm, _ = ref(t - h)
        np.testing.assert_allclose((qp - qm) / (2 * h), qd, atol=1e-6)
        np.testing.assert_allclose((qdp - qdm) / (2 * h), qdd, atol=1e-5)
    f = Fourier.random(2, harmonics=3, amplitude=[0.5, 0.2], q0=[1.0, -1.0], seed=4)
    q, _, _ = f(np.linspace(0, f.period, 3001))
    assert np.abs(q - f.q0).max(axis=0) == pytest.approx([0.5, 0.2], rel=1e-3)
    np.testing.assert_allclose(f(0.3)[0], f(0.3 + f.period)[0], atol=1e-12)  # periodic


def test_passivity_integral_equals_the_energy_change(puma):
    """int_0^T qd . tau dt == H(T) - H(0) (Spong eq. 9.117) along a controlled run, to integration
    accuracy, also with friction (minus the dissipated energy)."""
    ctl = PDGravity(puma, 60.0, 8.0, np.array([0.4, -0.3, 0.5, 0.0, 0.2, 0.0]))
    traj = kd.simulate(puma, 2.0, X0_PUMA, controller=ctl, dt=1e-3)
    bal = traj.energy_balance()
    assert abs(bal["work"][-1]) > 1.0  # the input does real work
    assert bal["relative"] < 1e-6
    # viscous friction only (Coulomb friction's sign switch makes the integrand discontinuous)
    import dataclasses

    rough = kd.robots.puma560(friction=True)
    links = [
        dataclasses.replace(l, joint=dataclasses.replace(l.joint, coulomb=0.0, coulomb_negative=None))
        for l in rough.links
    ]
    rough = rough.replace(links=links)
    assert rough.joints[0].viscous > 0
    traj = kd.simulate(rough, 1.0, X0_PUMA, controller=PDGravity(rough, 60.0, 8.0, np.zeros(6)), dt=1e-3)
    bal = traj.energy_balance()
    assert bal["dissipated"][-1] > 1.0
    assert bal["relative"] < 1e-6
    # the balance fails if the friction loss is left out
    assert abs(bal["dH"][-1] - bal["work"][-1]) > 100 * abs(bal["residual"][-1])


# ------------------------------------------------------------------ constrained systems
def sphere_by_hand(m=2.0) -> MechanicalSystem:
    """LaValle Ex. 13.14 written numerically: M = m I, phi = |q|^2 - 1, A = 2 q^T, dA/dt qd = 2 |qd|^2."""
    return MechanicalSystem(
        n=3,
        mass_matrix=lambda q: m * np.eye(3),
        bias=lambda q, qd: np.zeros(3),
        constraint_jacobian=lambda q: 2 * q[None, :],
        constraint_drift=lambda q, qd: np.array([2 * qd @ qd]),
        constraint=lambda q: np.array([q @ q - 1]),
        energy=lambda q, qd: 0.5 * m * qd @ qd,
        name="sphere particle (by hand)",
    )


def test_sphere_particle_by_hand_stays_on_the_sphere():
    x0 = np.r_[1.0, 0.0, 0.0, 0.0, 0.7, 0.7]
    traj = kd.simulate(sphere_by_hand(), 2.0, x0, dt=1e-3)
    pos, vel = traj.constraint_error.max(axis=0)
    assert pos < 1e-8 and vel < 1e-8
    c = np.cross(x0[:3], x0[3:])  # LaValle 13.178: a great circle in the plane c . q = 0
    assert np.abs(traj.q @ c).max() < 1e-10
    # without the dA/dt qd term (LaValle's printed 13.180) the particle leaves the sphere
    wrong = sphere_by_hand()
    wrong.constraint_drift = lambda q, qd: np.zeros(1)
    wrong.baumgarte = (0.0, 0.0)
    assert kd.simulate(wrong, 2.0, x0, dt=1e-3).constraint_error[:, 0].max() > 0.1


def test_sphere_particle_from_the_lagrangian_system():
    from kinedyn.symbolic import examples

    x0 = np.r_[0.0, 0.6, 0.8, 0.5, 0.48, -0.36]  # qd tangent to the sphere: q . qd = 0
    traj = kd.simulate(examples.sphere_particle(), 2.0, x0, dt=1e-3)
    pos, vel = traj.constraint_error.max(axis=0)
    assert pos < 1e-8 and vel < 1e-8
    assert np.abs(traj.H - traj.H[0]).max() < 1e-8
    hand = kd.simulate(sphere_by_hand(), 2.0, x0, dt=1e-3)
    assert np.abs(hand.q - traj.q).max() < 1e-10


def test_baumgarte_pulls_a_perturbed_start_back_to_the_constraint():
    x0 = np.r_[1.01, 0.0, 0.0, 0.0, 0.7, 0.7]  # 1 % off the sphere
    traj = kd.simulate(sphere_by_hand(), 2.0, x0, dt=1e-3, baumgarte=(10.0, 10.0))
    assert traj.constraint_error[0, 0] > 1e-2
    assert traj.constraint_error[-1, 0] < 1e-6


def closed_five_bar(g: float = 0.0):
    """Spong §9.4's parallelogram five-bar with four link angles a1..a4 and the loop closure as two
    holonomic constraints, in a horizontal plane (g = 0) or a vertical one (gravity -g along y; from
    the start state below it swings without passing the parallelogram's flat singular configuration,
    min |a1 - a2| = 1.7 rad)."""
    from kinedyn.symbolic import LagrangianSystem, coordinates

    l1, l2, lc1, lc2, lc3, lc4 = 1.0, 0.7, 0.5, 0.35, 0.5, 0.2
    m, I = [1.0, 0.8, 0.6, 0.5], [0.1, 0.05, 0.04, 0.03]
    (a1, a2, a3, a4), (d1, d2, d3, d4) = coordinates("a1 a2 a3 a4")
    u = lambda a: sp.Matrix([sp.cos(a), sp.sin(a)])  # noqa: E731
    bodies = [
        dict(mass=m[0], position=lc1 * u(a1), inertia=I[0], angular_velocity=d1),
        dict(mass=m[1], position=lc2 * u(a2), inertia=I[1], angular_velocity=d2),
        dict(mass=m[2], position=l2 * u(a2) + lc3 * u(a3), inertia=I[2], angular_velocity=d3),
        dict(mass=m[3], position=l1 * u(a1) - lc4 * u(a4), inertia=I[3], angular_velocity=d4),
    ]
    closure = list(l2 * u(a2) + l1 * u(a3) - (l1 * u(a1) + l2 * u(a4)))
    system = LagrangianSystem.from_bodies(
        [a1, a2, a3, a4],
        bodies,
        qd=[d1, d2, d3, d4],
        gravity=(0, -g),
        holonomic=closure,
        forces=[0] * 4,
        name="five-bar (closed)",
    )
    params = dict(
        l1=l1,
        l2=l2,
        lc1=lc1,
        lc2=lc2,
        lc3=lc3,
        lc4=lc4,
        g=g,
        m1=m[0],
        m2=m[1],
        m3=m[2],
        m4=m[3],
        I1=I[0],
        I2=I[1],
        I3=I[2],
        I4=I[3],
    )
    return system, params


@pytest.mark.parametrize("g", [0.0, 9.81])
def test_five_bar_stays_closed_and_matches_the_reduced_model(g):
    from kinedyn.symbolic import examples

    system, params = closed_five_bar(g)
    x0 = np.r_[0.3, 2.0, 0.3, 2.0, 0.2, 0.1, 0.2, 0.1]
    traj = kd.simulate(system, 1.0, x0, dt=1e-3)
    pos, vel = traj.constraint_error.max(axis=0)
    assert pos < 1e-8 and vel < 1e-8
    assert np.abs(traj.H - traj.H[0]).max() < 1e-9
    # the two-coordinate model of examples.five_bar() (links 3, 4 follow 1, 2) gives the same motion
    reduced = kd.simulate(examples.five_bar(), 1.0, np.r_[0.3, 2.0, 0.2, 0.1], dt=1e-3, params=params)
    assert np.abs(reduced.q - traj.q[:, :2]).max() < 1e-9
    assert np.abs(traj.q[:, 0] - traj.q[:, 1]).min() > 0.5  # away from the flat configuration


def test_lagrangian_system_needs_its_parameters():
    from kinedyn.symbolic import examples

    with pytest.raises(ValueError, match="give values for the parameters"):
        kd.simulate(examples.five_bar(), 0.1, np.zeros(4))


# ------------------------------------------------------------------ bad input and blow-ups
def test_bad_input_gives_clear_errors(puma):
    with pytest.raises(ValueError, match=r"x0 must be concatenate\(\[q0, qd0\]\) with 2 n = 12"):
        kd.simulate(puma, 1.0, np.zeros(6))
    with pytest.raises(ValueError, match="dt must be a positive"):
        kd.simulate(puma, 1.0, np.zeros(12), dt=0.0)
    with pytest.raises(ValueError, match="dt must be a positive"):
        kd.simulate(puma, 1.0, np.zeros(12), dt=-1e-3)
    with pytest.raises(ValueError, match="t_span must end after it starts"):
        kd.simulate(puma, (1.0, 0.5), np.zeros(12))
    with pytest.raises(ValueError, match="unknown method"):
        kd.simulate(puma, 1.0, np.zeros(12), method="leapfrog")
    with pytest.raises(ValueError, match="u has 7 samples"):
        kd.simulate(puma, 0.01, np.zeros(12), u=np.zeros((7, 6)))
    with pytest.raises(ValueError, match="non-finite"):
        kd.simulate(puma, 0.01, np.r_[np.nan, np.zeros(11)])
    with pytest.raises(TypeError, match="LagrangianSystem"):
        kd.simulate("puma", 0.01, np.zeros(12))
    with pytest.raises(ValueError, match="t_span must be a duration T or a pair"):
        kd.simulate(puma, "1 s", np.zeros(12))
    with pytest.raises(ValueError, match="dt must be a positive step in seconds, got 'fast'"):
        kd.simulate(puma, 1.0, np.zeros(12), dt="fast")
    for bad in (-1.0, float("nan")):  # a negative one stopped at step 0 as a "blow-up"; NaN never stopped
        with pytest.raises(ValueError, match="max_speed must be a positive speed"):
            kd.simulate(puma, 0.01, np.zeros(12), max_speed=bad)
    with pytest.raises(ValueError, match="rtol and atol must be positive"):  # SciPy only warned
        kd.simulate(puma, 0.01, np.zeros(12), method="rk45", rtol=-1.0)


def test_controller_errors_name_the_problem(puma):
    with pytest.raises(ValueError, match="made for 3 joints but 'puma560' has 6"):  # was a NumPy broadcast error
        kd.simulate(puma, 0.01, np.zeros(12), controller=kd.simulate.PD(1.0, 1.0, np.zeros(3)))
    with pytest.raises(ValueError, match="Kd contains a non-finite gain"):
        kd.simulate.PD(1.0, [1.0, np.nan], np.zeros(2))
    with pytest.raises(ValueError, match="set point contains NaN"):
        kd.simulate.PDGravity(puma, 1.0, 1.0, np.full(6, np.nan))


def test_non_finite_controller_torque_is_reported(puma):
    def bad(t, q, qd):
        tau = np.zeros(6)
        if t >= 0.05:
            tau[2] = np.nan
        return tau

    for method in ("rk4", "rk45"):
        with pytest.raises(
            NonFiniteTorqueError, match=r"non-finite torque \(nan\) at joint 'q3' at t = 0\.0[5-9]"
        ) as info:
            kd.simulate(puma, 0.2, X0_PUMA, controller=bad, method=method)
        assert isinstance(info.value, ValueError)
    with pytest.raises(ValueError, match="returned torques of shape"):
        kd.simulate(puma, 0.01, X0_PUMA, controller=lambda t, q, qd: np.zeros(3))


def test_blow_up_stops_with_when_and_where(puma):
    # a destabilising "controller" (positive velocity feedback) drives joint speeds past max_speed
    ctl = lambda t, q, qd: 500.0 * qd  # noqa: E731
    with pytest.raises(SimulationError, match=r"blew up at t = [0-9.]+ s \(step \d+ of 3000\).*joint 'q\d'") as info:
        kd.simulate(puma, 3.0, X0_PUMA, controller=ctl, max_speed=1e3)
    err = info.value
    partial = err.trajectory
    assert isinstance(partial, Trajectory) and 0 < err.t < 3.0
    assert np.all(np.isfinite(partial.q)) and partial.t[-1] <= err.t + 1e-12
    assert np.abs(partial.qd[-1]).max() <= 1e3
    # native path with a huge constant torque
    with pytest.raises(SimulationError, match="blew up") as info:
        kd.simulate(puma, 1.0, X0_PUMA, u=np.full(6, 1e9), max_speed=1e4)
    assert info.value.kind == "diverged" and np.all(np.isfinite(info.value.trajectory.q))


# ------------------------------------------------------------------ exports
def test_trajectory_exports(tmp_path, puma):
    import matplotlib

    matplotlib.use("Agg")
    traj = kd.simulate(puma, 0.2, X0_PUMA, record_every=10)
    csv = traj.to_csv(tmp_path / "t.csv")
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    header = csv.read_text().splitlines()[0].split(",")
    assert header[:2] == ["t", "q[q1]"] and header[-3:] == ["K", "P", "H"]
    np.testing.assert_allclose(data[:, 0], traj.t)
    np.testing.assert_allclose(data[:, -1], traj.H)
    z = np.load(traj.to_npz(tmp_path / "t.npz"))
    np.testing.assert_array_equal(z["q"], traj.q)
    assert list(z["names"]) == puma.joint_names
    fig = traj.plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").stat().st_size > 1000 and len(fig.axes) == 4
    gif = traj.animate(tmp_path / "t.gif", fps=10)
    assert gif.read_bytes()[:3] == b"GIF"
    planar = kd.simulate(kd.robots.planar_2r(), 0.3, np.r_[0.3, -0.7, 1.0, 3.0])
    html = planar.animate(tmp_path / "p.html", fps=10)
    assert "<script" in html.read_text()
    with pytest.raises(ValueError, match=".gif, .html or .mp4"):
        planar.animate(tmp_path / "p.avi")


def test_kd_simulate_is_the_function_and_the_package():
    import kinedyn.simulate as pkg

    assert kd.simulate is pkg and callable(kd.simulate)
    assert kd.Trajectory is Trajectory and kd.simulate.PD is PD
    assert math.isclose(kd.simulate(kd.robots.planar_2r(), 0.01, np.zeros(4)).t[-1], 0.01)


def test_cli_simulate_json_and_files(tmp_path, capsys):
    import json

    from kinedyn.cli import main

    png = tmp_path / "out.png"
    code = main(
        [
            "simulate",
            "planar_2r",
            "--t",
            "1",
            "--controller",
            "pdg",
            "--goal",
            "0.5",
            "-0.3",
            "--plot",
            str(png),
            "--json",
        ]
    )
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and png.stat().st_size > 1000
    assert doc["controller"] == "PD + gravity compensation" and doc["samples"] == 1001
    robot = kd.robots.planar_2r()
    ref = kd.simulate(robot, 1.0, np.zeros(4), controller=PDGravity(robot, 100.0, 20.0, [0.5, -0.3]))
    np.testing.assert_allclose(doc["q_final"], ref.q[-1], rtol=0, atol=1e-14)
    code = main(["simulate", "planar_2r", "--dt", "0"])
    assert code == 1 and "argument --dt: must be a positive" in capsys.readouterr().err
