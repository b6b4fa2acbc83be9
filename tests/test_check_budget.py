"""kinedyn check on real robots: right with Coulomb friction (passivity is the rigid-body
dynamics' property, friction's dissipation a check of its own) and bounded in time (the
inertia-bound search stops at its budget and says its bound is sampled)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinedyn as kd
from kinedyn import analysis
from kinedyn.cli import main

pytest.importorskip("kinedyn._core", reason="the native module is not built")


def with_coulomb(robot, level: float):
    links = [dataclasses.replace(l, joint=dataclasses.replace(l.joint, coulomb=level)) for l in robot.description.links]
    return robot.replace(links=links)


def test_passivity_holds_on_an_arm_with_strong_coulomb_friction():
    # 80 N m of Coulomb friction on the tutorial's arm: the joints stick and slip under the PD loop,
    # and RK4 across the sign switches left a balance residual of 1.2e-3 (> 1e-3, reported failed)
    robot = with_coulomb(kd.robots.planar_2r(), 80.0)
    report = analysis.check_properties(robot, samples=20)
    passivity = next(c for c in report.checks if c.name.startswith("passivity"))
    assert passivity.passed and passivity.residual < 1e-6, passivity.detail
    assert "without Coulomb friction" in passivity.detail
    assert report["friction dissipates: qd . friction(qd) >= 0"].passed
    assert report.passed


def test_friction_that_puts_energy_in_fails_its_check(monkeypatch):
    robot = with_coulomb(kd.robots.planar_2r(), 1.0)
    # a sign slip: friction pushing (the model refuses negative levels, so the slip is in the code)
    monkeypatch.setattr(kd.Robot, "friction_torque", lambda self, qd: -np.asarray(qd, dtype=float))
    check = analysis.check_properties(robot, samples=20)["friction dissipates: qd . friction(qd) >= 0"]
    assert not check.passed and check.residual > 0


def test_inertia_bound_search_stops_at_its_budget_and_says_sampled():
    robot = kd.robots.puma560()
    spent = analysis.check_properties(robot, samples=20, time_budget=0.0)[
        "inertia bounds lambda_min I <= M(q) <= lambda_max I"
    ]
    assert spent.status == "sampled" and "a sampled bound, not a searched one" in spent.detail
    assert spent.data["searches"] < spent.data["searches_planned"]
    # the sampled bound is attained where it says (an estimate of the searched one, never below it)
    full = analysis.check_properties(robot, samples=20)["inertia bounds lambda_min I <= M(q) <= lambda_max I"]
    assert full.status == "searched" and full.data["searches"] == full.data["searches_planned"]
    assert full.data["lambda_min"] <= spent.data["lambda_min"] + 1e-12
    q = spent.data["q_lambda_min"]
    assert np.linalg.eigvalsh(robot.mass_matrix(q))[0] == pytest.approx(spent.data["lambda_min"], rel=1e-12)


def test_cli_check_takes_a_budget(capsys):
    code = main(["check", "elbow_3r", "--samples", "20", "--budget", "0.001", "--json"])
    out = capsys.readouterr().out
    assert code == 0
    assert '"status": "sampled"' in out and "time budget of 0.001 s" in out
