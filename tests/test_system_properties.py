"""Property checks for a LagrangianSystem (issue 12 §6): M symmetric, dM/dt - 2C skew-symmetric,
dM/dt = C + C^T and C qd + g = the Euler-Lagrange bias proven by exact simplification; M positive
definite and the energy balance measured (for constrained systems also: the constraint forces do no
work and the motion stays on the manifold)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import kinedyn as kd
from kinedyn.robots import examples as rex
from kinedyn.symbolic import LagrangianSystem, coordinates
from kinedyn.symbolic import examples as ex
from kinedyn.symbolic.mechanisms import closed_chain_system, loop_closure

EXACT = [
    "M symmetric (exact)",
    "dM/dt - 2C skew-symmetric (exact)",
    "dM/dt == C + C^T (exact)",
    "C qd + g == Euler-Lagrange bias (exact)",
]
CONSTRAINED = ["constraint forces do no work", "motion stays on the constraint manifold"]


def _values(system, seed=0):
    rng = np.random.default_rng(seed)
    state = {c.name for c in system.q + system.qd} | {system.t.name}
    names = sorted(
        {s.name for e in [system.L, *system.B, *system.A, *system.holonomic] for s in sp.sympify(e).free_symbols}
        - state
    )
    return {k: float(rng.uniform(0.5, 2.0)) for k in names}


def _five_bar_trees():
    return closed_chain_system(
        rex.five_bar_chains(), loop_closure(*rex.five_bar_chains()), name="five-bar (trees + closure)"
    )


@pytest.mark.parametrize(
    "factory, constrained",
    [
        (ex.remotely_driven_arm, False),
        (ex.five_bar, False),
        (ex.geared_link, False),
        (ex.falling_particle, False),
        (ex.sphere_particle, True),
        (_five_bar_trees, True),
    ],
    ids=["remote", "five_bar", "geared_damped", "falling", "sphere", "five_bar_trees"],
)
def test_properties_hold_and_are_proven_exactly(factory, constrained):
    system = factory()
    report = kd.analysis.check_system_properties(system, _values(system))
    names = [c.name for c in report.checks]
    assert report.passed, str(report)
    for name in EXACT:
        assert name in names and report[name].residual == 0.0
    assert ("constraint forces do no work: int qd . A^T lambda dt == 0" in names) == constrained
    assert ("motion stays on the constraint manifold" in names) == constrained
    passivity = report["passivity"]
    assert abs(passivity.data["work"]) > 1e-3  # the forces did work
    if factory is ex.geared_link:
        assert passivity.data["dissipated"] > 1e-3  # and the damping dissipated some


def test_non_natural_lagrangian_gets_only_the_checks_that_apply():
    """A charge in a magnetic field (L = |qd|^2 / 2 + b (x yd - y xd) / 2): not natural, C is not
    defined by Christoffel symbols, so only the symmetry of M is proven; the energy balance holds."""
    (x, y), (xd, yd) = coordinates("x y")
    b = sp.Symbol("b", positive=True)
    system = LagrangianSystem(
        [x, y], L=(xd**2 + yd**2) / 2 + b * (x * yd - y * xd) / 2, qd=[xd, yd], name="charge in a field"
    )
    report = system.check_properties({"b": 1.5})
    assert report.passed, str(report)
    names = [c.name for c in report.checks]
    assert "M symmetric (exact)" in names and "dM/dt - 2C skew-symmetric (exact)" not in names
    assert abs(report["passivity"].data["work"]) > 1e-3


def _with(eom, C):
    from kinedyn.symbolic.eom import EquationsOfMotion

    return EquationsOfMotion(
        eom.q, eom.qd, eom.qdd, eom.M, C, eom.g, K=eom.K, P=eom.P, friction=eom.friction, extra=eom.extra
    )


def test_exact_checks_catch_a_wrong_coriolis_matrix(monkeypatch):
    system = ex.remotely_driven_arm()
    eom = system.equations_of_motion()
    # C^T passes skew symmetry and dM/dt = C + C^T, and fails C qd + g = bias
    monkeypatch.setattr(system, "equations_of_motion", lambda: _with(eom, eom.C.T))
    report = kd.analysis.check_system_properties(system, exact_only=True)
    assert report["dM/dt - 2C skew"].passed and report["dM/dt == C + C^T"].passed
    assert not report["C qd + g"].passed and not report.passed
    # 2C fails skew symmetry
    monkeypatch.setattr(system, "equations_of_motion", lambda: _with(eom, 2 * eom.C))
    report = kd.analysis.check_system_properties(system, exact_only=True)
    assert not report["dM/dt - 2C skew"].passed and not report["dM/dt == C + C^T"].passed


def test_energy_balance_catches_a_wrong_energy(monkeypatch):
    system = ex.falling_particle()
    values = _values(system)
    kinetic_only = system.K  # H without the potential energy: the work of gravity goes missing
    monkeypatch.setattr(system, "energy", lambda: kinetic_only)
    report = kd.analysis.check_system_properties(system, values)
    assert not report["passivity"].passed


def test_missing_parameters_are_named_and_exact_only_needs_none():
    system = ex.five_bar()
    with pytest.raises(ValueError, match="lc3"):
        kd.analysis.check_system_properties(system)
    report = kd.analysis.check_system_properties(system, exact_only=True)
    assert [c.name for c in report.checks] == EXACT and report.passed
