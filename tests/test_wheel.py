"""The wheel built by scripts/build-wheels installs and works where there is no Rust toolchain.

In a fresh virtual environment, on a PATH without `cargo` or `rustc`, from a folder outside the
source tree (so neither python/ nor PYTHONPATH can supply kinedyn), the wheel is installed with pip
and must: import its own compiled core, reproduce known numbers, and run the README's main job
(`kinedyn report`).

Which wheel: $KINEDYN_WHEEL (set by .ci/run, which builds the wheel once per run; missing file =
failure), else the one in dist/. Without either the test is skipped with the command to build one.
The venv sees the running interpreter's site-packages (not its base's) for the dependencies (numpy, sympy, ...: no download), but
kinedyn itself is installed into the venv (--ignore-installed) and the test checks it is imported
from there; the wheel's declared dependencies are checked against what the venv imports.
"""

from __future__ import annotations

import json
import os
import shutil
import site
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _wheel() -> Path:
    given = os.environ.get("KINEDYN_WHEEL")
    if given:
        path = Path(given).resolve()  # pip runs in a scratch folder
        assert path.is_file(), f"KINEDYN_WHEEL={given} is not a file"
        return path
    found = sorted((ROOT / "dist").glob("kinedyn-*.whl"))
    if not found:
        pytest.skip("no wheel in dist/: run scripts/build-wheels (CI sets KINEDYN_WHEEL)")
    assert len(found) == 1, f"several wheels in dist/: {[p.name for p in found]}"
    return found[0]


# Runs inside the venv. Known values: README's "A taste" (the tutorial's Q1-Q2 at q = (167.028,
# -156.44) deg) and the closed-form mass matrix of two uniform rods (Spong §7.4.1 with lc = l/2,
# I = m l^2 / 12): M11 = m1 l1^2/3 + m2 (l1^2 + l2^2/3 + l1 l2 c2), M12 = m2 (l2^2/3 + l1 l2 c2 / 2),
# M22 = m2 l2^2 / 3; g(q) = the static torques of the same rods.
SMOKE = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    import kinedyn as kd
    import kinedyn._core as core

    robot = kd.robots.planar_2r()
    q = np.radians([167.028, -156.44])
    J = robot.jacobian(q)
    v = J[:2] @ [1.0, 3.0]
    tau = J[:2].T @ [30.0, -20.0]
    assert np.allclose(v, [-2.654, 9.847], atol=5e-4), v
    assert np.allclose(tau, [-50.0, -75.52], atol=5e-3), tau

    l1, l2, m1, m2, g0 = 2.0, 3.0, 1.0, 1.0, 9.81
    q = np.array([0.3, -1.1])
    c2 = np.cos(q[1])
    M = np.array([[m1 * l1**2 / 3 + m2 * (l1**2 + l2**2 / 3 + l1 * l2 * c2), m2 * (l2**2 / 3 + l1 * l2 * c2 / 2)],
                  [m2 * (l2**2 / 3 + l1 * l2 * c2 / 2), m2 * l2**2 / 3]])
    assert np.allclose(robot.mass_matrix(q), M, rtol=1e-12, atol=1e-12), robot.mass_matrix(q)
    g = g0 * np.array([(m1 * l1 / 2 + m2 * l1) * np.cos(q[0]) + m2 * l2 / 2 * np.cos(q.sum()), m2 * l2 / 2 * np.cos(q.sum())])
    assert np.allclose(robot.gravity_torque(q), g, rtol=1e-12, atol=1e-12), robot.gravity_torque(q)
    qd, qdd = np.array([0.7, -0.2]), np.array([0.1, 0.4])
    assert np.allclose(robot.forward_dynamics(q, qd, robot.inverse_dynamics(q, qd, qdd)), qdd, atol=1e-10)

    puma = kd.robots.puma560()
    Q = puma.random_configuration(rng=0, size=1000)
    assert puma.forward_kinematics(Q).shape == (1000, 6, 4, 4)

    json.dump({"kinedyn": kd.__file__, "core": core.__file__, "version": kd.__version__}, sys.stdout)
    """
)


def _see_host_packages(env_dir: Path) -> None:
    """Let the venv import what the running interpreter imports, after its own site-packages.

    `venv --system-site-packages` would expose the *base* interpreter's packages: from inside a
    virtual environment (how most people run the suite) that base has none of the dependencies,
    whereas a conda-like or system interpreter has them in its own prefix. `site.getsitepackages()`
    names exactly the folders this interpreter reads (its venv's, and its base's when that venv
    sees them); `site.addsitedir` appends them and reads their .pth files, so kinedyn installed into
    the new venv still comes first.
    """
    folders = [*site.getsitepackages(), site.getusersitepackages()]
    folders = [f for f in dict.fromkeys(folders) if Path(f).is_dir()]
    purelib = subprocess.run(
        [str(env_dir / "bin" / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    lines = [f"import site; site.addsitedir({f!r})" for f in folders]
    (Path(purelib) / "_kinedyn_test_host_packages.pth").write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    wheel = _wheel()
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
    assert any(n.startswith("kinedyn/_core.") and n.endswith(".so") for n in names), names
    assert "kinedyn/_core.pyi" in names and "kinedyn/py.typed" in names
    assert not any(n.endswith((".rs", "Cargo.toml")) for n in names), "Rust sources in the wheel"

    home = tmp_path_factory.mktemp("wheel")
    env_dir = home / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(env_dir)], check=True)
    _see_host_packages(env_dir)
    bin_dir = env_dir / "bin"
    path = os.pathsep.join([str(bin_dir), "/usr/bin", "/bin"])
    for tool in ("cargo", "rustc", "maturin"):
        assert shutil.which(tool, path=path) is None, f"{tool} is on the test PATH {path}"
    env = {
        "PATH": path,
        "HOME": str(home),
        "LANG": "C.UTF-8",
        "MPLBACKEND": "Agg",
        "PIP_DISABLE_PIP_VERSION_CHECK": "1",
    }
    subprocess.run(
        [
            str(bin_dir / "python"),
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-index",
            "--no-deps",
            "--ignore-installed",
            str(wheel),
        ],
        check=True,
        cwd=home,
        env=env,
    )
    return env_dir, env, home


def _run(venv, *args, timeout=600):
    env_dir, env, home = venv
    return subprocess.run(args, cwd=home, env=env, capture_output=True, text=True, timeout=timeout)


def test_wheel_imports_its_own_core_and_computes_known_values(venv):
    env_dir = venv[0]
    done = _run(venv, str(env_dir / "bin" / "python"), "-c", SMOKE)
    assert done.returncode == 0, done.stderr
    where = json.loads(done.stdout)
    venv_root = str(env_dir.resolve())
    assert where["kinedyn"].startswith(venv_root), f"kinedyn imported from {where['kinedyn']}, not the venv"
    assert where["core"].startswith(venv_root) and where["core"].endswith(".abi3.so"), where["core"]


def test_wheel_dependencies_are_met(venv):
    """Every Requires-Dist of the wheel without an extra is satisfied in the venv (pip check for it)."""
    env_dir = venv[0]
    check = textwrap.dedent(
        """
        from importlib.metadata import distribution, version
        from packaging.requirements import Requirement
        reqs = [Requirement(r) for r in distribution("kinedyn").requires or []]
        core = [r for r in reqs if r.marker is None or r.marker.evaluate({"extra": ""})]
        assert core, reqs
        bad = [str(r) for r in core if not r.specifier.contains(version(r.name), prereleases=True)]
        assert not bad, bad
        print(len(core))
        """
    )
    done = _run(venv, str(env_dir / "bin" / "python"), "-c", check)
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) >= 7


def test_wheel_runs_the_readme_job(venv):
    """`kinedyn report` (the README's quick start) from the venv's console script."""
    env_dir, env, home = venv
    done = _run(venv, str(env_dir / "bin" / "kinedyn"), "report")
    assert done.returncode == 0, done.stderr
    report = home / "report.html"
    assert "planar_2r: report written to" in done.stdout, done.stdout
    text = report.read_text()
    assert report.stat().st_size > 100_000 and "</html>" in text
    assert "properties: all hold" in done.stdout, done.stdout
