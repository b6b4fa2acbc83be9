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
import resource
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


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float] | None:
    """(wall, CPU) seconds of the command; CPU (user + system of the child) depends far less on what
    else the machine runs than wall time does."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True)
    elapsed = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return (elapsed, cpu) if done.returncode == 0 else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(PYTHON_DIR), os.environ.get("PYTHONPATH", "")]))
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in COMMANDS}
    for _ in range(args.repeat):
        for name, command in COMMANDS.items():
            t = timed(command, env)
            if t is not None:
                times[name].append(t)
    best = {name: (min(w for w, _ in ts), min(c for _, c in ts)) for name, ts in times.items() if ts}
    print(f"best of {args.repeat}, a fresh interpreter each: wall s, CPU s")
    for name in COMMANDS:
        if name in best:
            print(f"  {name:18s} {best[name][0]:.3f}  {best[name][1]:.3f}")
        else:
            print(f"  {name:18s} failed (not installed?)")
    if "import pinocchio" in best:
        peer = best["import pinocchio"]
        for name in ("import kinedyn", "kinedyn fk ur5"):
            if name in best:
                wall, cpu = best[name][0] / peer[0], best[name][1] / peer[1]
                print(f"  {name} / import pinocchio: wall {wall:.2f}, CPU {cpu:.2f}")
    loaded = subprocess.run(
        [sys.executable, "-c", f"import sys, kinedyn; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"],
        env=env,
        capture_output=True,
        text=True,
    ).stdout.strip()
    print(f"heavy libraries loaded by import kinedyn: {loaded or 'none'}")


if __name__ == "__main__":
    main()
