"""Start-up: ``import kinedyn`` and ``kinedyn fk ur5`` (end to end, a fresh interpreter each time)
beside ``import pinocchio`` and a bare interpreter, in the same run, as ratios (issue 23, "Start
fast": targets 0.25 s and 0.35 s on a quiet machine, where ``import pinocchio`` takes about 0.2 s).

Each command runs ``--repeat`` times (default 7) interleaved with the others, so that a machine
whose load changes during the run slows all of them alike; the minimum of each is reported (the
run least disturbed by other work). Also lists the heavy libraries ``import kinedyn`` loaded
(none of SymPy, SciPy, plotly, trimesh, rich is expected).

Run: PYTHONPATH=python python3 benches/bench_import.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

PYTHON_DIR = Path(__file__).resolve().parents[1] / "python"
HEAVY = ("sympy", "scipy", "plotly", "trimesh", "rich", "matplotlib", "pandas", "jinja2", "yaml")

COMMANDS = {
    "python -c pass": [sys.executable, "-c", "pass"],
    "import numpy": [sys.executable, "-c", "import numpy"],
    "import pinocchio": [sys.executable, "-c", "import pinocchio"],
    "import kinedyn": [sys.executable, "-c", "import kinedyn"],
    "kinedyn fk ur5": [sys.executable, "-m", "kinedyn", "fk", "ur5"],
}


def wall(command: list[str], env: dict[str, str]) -> float | None:
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True)
    elapsed = time.perf_counter() - start
    return elapsed if done.returncode == 0 else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(PYTHON_DIR), os.environ.get("PYTHONPATH", "")]))
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(args.repeat):
        for name, command in COMMANDS.items():
            t = wall(command, env)
            if t is not None:
                times[name].append(t)
    best = {name: min(ts) for name, ts in times.items() if ts}
    print(f"best of {args.repeat} (s), a fresh interpreter each:")
    for name in COMMANDS:
        print(f"  {name:18s} {best[name]:.3f}" if name in best else f"  {name:18s} failed (not installed?)")
    if "import pinocchio" in best:
        peer = best["import pinocchio"]
        for name in ("import kinedyn", "kinedyn fk ur5"):
            print(f"  {name} / import pinocchio = {best[name] / peer:.2f}")
    loaded = subprocess.run(
        [sys.executable, "-c", f"import sys, kinedyn; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"],
        env=env,
        capture_output=True,
        text=True,
    ).stdout.strip()
    print(f"heavy libraries loaded by import kinedyn: {loaded or 'none'}")


if __name__ == "__main__":
    main()
