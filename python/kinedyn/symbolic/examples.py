"""The seed's example mechanisms as Lagrangian systems (each derived here from its geometry; the
seed's printed formulas are not copied, several carry misprints — see docs/symbolic.md).

- :func:`remotely_driven_arm`: Spong §9.4, planar elbow with the second joint driven from the base
  through a belt: coordinates p1, p2 are the absolute link angles, not joint angles (bodies written
  here); :func:`kinedyn.robots.examples.remotely_driven_arm_from_robot`: the same from the planar-elbow Robot and its drive
  map q = A p (:func:`kinedyn.symbolic.mechanisms.change_coordinates`).
- :func:`five_bar`: Spong §9.4, the parallelogram five-bar linkage; D is diagonal and constant exactly
  when m3 l2 lc3 = m4 l1 lc4 (bodies written here); :func:`kinedyn.robots.examples.five_bar_chains` /
  :func:`kinedyn.robots.examples.five_bar_from_chains`: the same assembled from two serial Robots and the loop closure
  (:func:`kinedyn.symbolic.mechanisms.closed_chain`).
- :func:`four_bar_linkage`: SymPy mechanics' four-bar (3 relative joint angles, 2 loop-closure
  constraints), solved numerically per evaluation by :meth:`LagrangianSystem.numeric`.
- :func:`sphere_particle`: LaValle Example 13.14, a particle on the unit sphere (holonomic constraint).
- :func:`falling_particle`: LaValle Example 13.11.
- :func:`simple_variational`: LaValle Example 13.10, L = x^3 + xd^2.
- :func:`geared_link`: Spong Example 9.1, one link through an r:1 gear train with rotor inertia J_m,
  and motor damping B_m reflected to the link (r^2 J_m, r^2 B_m); also :func:`kinedyn.robots.examples.geared_link_robot`.
"""

from __future__ import annotations

import warnings

import sympy as sp

from .systems.system import LagrangianSystem, coordinates

__all__ = [
    "remotely_driven_arm",
    "five_bar",
    "four_bar_linkage",
    "sphere_particle",
    "falling_particle",
    "simple_variational",
    "geared_link",
]


def _u(angle):
    return sp.Matrix([sp.cos(angle), sp.sin(angle)])


def remotely_driven_arm() -> LagrangianSystem:
    """Two links in a vertical plane; p1 = angle of link 1, p2 = angle of link 2, both from the x axis
    (the belt from the base motor sets link 2's absolute angle). Centres of mass at lc1 along link 1
    and l1 along link 1 + lc2 along link 2; angular velocities pd1, pd2; gravity -g along y."""
    l1, lc1, lc2, m1, m2, I1, I2, g = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2 g", positive=True)
    (p1, p2), (pd1, pd2) = coordinates("p1 p2")
    bodies = [
        dict(mass=m1, position=lc1 * _u(p1), inertia=I1, angular_velocity=pd1),
        dict(mass=m2, position=l1 * _u(p1) + lc2 * _u(p2), inertia=I2, angular_velocity=pd2),
    ]
    return LagrangianSystem.from_bodies(
        [p1, p2], bodies, gravity=(0, -g), qd=[pd1, pd2], name="remotely driven two-link arm"
    )


def five_bar() -> LagrangianSystem:
    """Parallelogram linkage with vertices O, A = l1 u(q1), B = l2 u(q2), A + l2 u(q2) (u(a) = (cos a, sin a)).
    Link 1 (O to A) turns with q1, link 2 (O to B) with q2; link 3 joins B to the far vertex, parallel
    to link 1 (length l1), centre of mass lc3 from B; link 4 is hinged at A, parallel to link 2, and
    carries the far vertex at l2 from A; its centre of mass is lc4 from A on the other side of the
    hinge (a counterweight). Links 1 and 3 turn with q1, links 2 and 4 with q2. Gravity -g along y."""
    l1, l2, lc1, lc2, lc3, lc4, g = sp.symbols("l1 l2 lc1 lc2 lc3 lc4 g", positive=True)
    m = sp.symbols("m1:5", positive=True)
    I = sp.symbols("I1:5", positive=True)
    (q1, q2), (qd1, qd2) = coordinates("q1 q2")
    positions = [lc1 * _u(q1), lc2 * _u(q2), l2 * _u(q2) + lc3 * _u(q1), l1 * _u(q1) - lc4 * _u(q2)]
    omegas = [qd1, qd2, qd1, qd2]
    bodies = [dict(mass=m[i], position=positions[i], inertia=I[i], angular_velocity=omegas[i]) for i in range(4)]
    return LagrangianSystem.from_bodies([q1, q2], bodies, gravity=(0, -g), qd=[qd1, qd2], name="five-bar linkage")


def four_bar_linkage() -> LagrangianSystem:
    """The four-bar of SymPy mechanics' ``test_four_bar_linkage_with_manual_constraints``: uniform
    links of lengths l1..l4 and density rho (mass rho l, inertia rho l^3 / 12 about the centre), link
    1 fixed along x with its centre at the origin, relative joint angles q1, q2, q3 (absolute angles
    q1, q1 + q2, q1 + q2 + q3), no gravity; the loop closes when link 4's far end reaches link 1's
    other end: l1 + sum_k l_k cos(a_k) = 0, sum_k l_k sin(a_k) = 0 (k = 2, 3, 4)."""
    (q1, q2, q3), (qd1, qd2, qd3) = coordinates("q1 q2 q3")
    l1, l2, l3, l4, rho = sp.symbols("l1:5 rho", positive=True)
    absolute = [q1, q1 + q2, q1 + q2 + q3]
    rates = [qd1, qd1 + qd2, qd1 + qd2 + qd3]
    joint = sp.Matrix([l1 / 2, 0])
    bodies = []
    for length, angle, rate in zip((l2, l3, l4), absolute, rates):
        bodies.append(
            dict(
                mass=rho * length,
                position=joint + length / 2 * _u(angle),
                inertia=rho * length**3 / 12,
                angular_velocity=rate,
            )
        )
        joint = joint + length * _u(angle)
    closure = joint - sp.Matrix([-l1 / 2, 0])
    return LagrangianSystem.from_bodies(
        [q1, q2, q3], bodies, qd=[qd1, qd2, qd3], holonomic=list(closure), forces=[0, 0, 0], name="four-bar linkage"
    )


def sphere_particle(m=2) -> LagrangianSystem:
    """A particle of mass m on the unit sphere, no gravity: L = m |qd|^2 / 2, g_c = |q|^2 - 1 = 0."""
    q, qd = coordinates("q1 q2 q3")
    K = sp.Rational(1, 2) * m * sum(v**2 for v in qd) if not isinstance(m, float) else 0.5 * m * sum(v**2 for v in qd)
    return LagrangianSystem(
        q, K=K, P=0, qd=qd, holonomic=[sum(x**2 for x in q) - 1], forces=[0, 0, 0], name="particle on a sphere"
    )


def falling_particle() -> LagrangianSystem:
    """A particle of mass m in R^3 with gravity -g along q3: K = m |qd|^2 / 2, P = m g q3."""
    m, g = sp.symbols("m g", positive=True)
    q, qd = coordinates("q1 q2 q3")
    return LagrangianSystem(
        q, K=m * sum(v**2 for v in qd) / 2, P=m * g * q[2], qd=qd, forces=[0, 0, 0], name="falling particle"
    )


def simple_variational() -> LagrangianSystem:
    """L(x, xd) = x^3 + xd^2: the Euler-Lagrange equation is 2 xdd - 3 x^2 = 0."""
    (x,), (xd,) = coordinates("x")
    return LagrangianSystem([x], L=x**3 + xd**2, qd=[xd], forces=[0], name="simple variational problem")


def geared_link() -> LagrangianSystem:
    """One link (inertia J_l about its joint, mass M, centre of mass ell from the joint) driven
    through an r:1 gear (theta_m = r theta) by a motor of rotor inertia J_m, motor torque tau_m and
    motor viscous damping B_m. Coordinate: the link angle theta (theta = 0 hanging down).
    K = J_m (r thetad)^2 / 2 + J_l thetad^2 / 2; P = M g ell (1 - cos theta); the motor's torque
    and damping reach the link through the gear by virtual work: u = r tau_m, B = r^2 B_m thetad."""
    J_l, J_m, M, g, ell, r, B_m, tau_m = sp.symbols("J_l J_m M g ell r B_m tau_m", positive=True)
    (th,), (thd,) = coordinates("theta")
    K = J_m * (r * thd) ** 2 / 2 + J_l * thd**2 / 2
    P = M * g * ell * (1 - sp.cos(th))
    return LagrangianSystem(
        [th], K=K, P=P, qd=[thd], forces=[r * tau_m], B=[r**2 * B_m * thd], name="geared single link"
    )


# Built from Robots, so they live above the Robot facade (kinedyn.robots.examples); their old names here
# keep working for one release.
_MOVED = ("remotely_driven_arm_from_robot", "five_bar_chains", "five_bar_from_chains", "geared_link_robot")


def __getattr__(name: str):
    if name in _MOVED:
        warnings.warn(
            f"kinedyn.symbolic.examples.{name} moved to kinedyn.robots.examples.{name}",
            DeprecationWarning,
            stacklevel=2,
        )
        from ..robots import examples  # the deprecated forwarder: the one upward import, gone with it

        return getattr(examples, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
