"""Ctrl-C stops long work: the command line exits 130 without a traceback even where a library
swallows the interrupt (kinedyn._ui.interrupts), and long native work stops inside its loop: the
simulator's steps, the batch runner's chunks, a batch IK's targets (each polls a cancellation flag
that the binding sets when a signal handler raises, crates/kinedyn-py/src/guard.rs).

Each test waits for the child to say where it is before interrupting it, and asserts behaviour
(the status, the output) with generous time limits, never a speed: they hold on a loaded machine."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import kinedyn as kd

pytestmark = pytest.mark.skipif(not hasattr(signal, "pthread_kill"), reason="POSIX signals")


def child_env() -> dict[str, str]:
    return dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([str(Path(kd.__file__).parents[1]), os.environ.get("PYTHONPATH", "")]),
        PYTHONFAULTHANDLER="1",
    )


def start(code: str, env: dict[str, str] | None = None) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**child_env(), **(env or {})},
    )


def wait_for_line(proc: subprocess.Popen, text: str, timeout: float = 180.0) -> None:
    """Read the child's stdout until a line holds ``text`` (the child is then where it says)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if text in line:
            return
        if not line and proc.poll() is not None:
            pytest.fail(f"the child ended before saying '{text}': {proc.communicate()}")
    proc.kill()
    pytest.fail(f"the child did not say '{text}' within {timeout} s")


def finish(proc: subprocess.Popen, timeout: float = 60.0) -> tuple[str, str]:
    try:
        return proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGABRT)  # its faulthandler (PYTHONFAULTHANDLER) prints every thread
        out, err = proc.communicate(timeout=60)
        pytest.fail(f"the child did not exit within {timeout} s of SIGINT; its threads when aborted:\n{err[-8000:]}")


# a command whose run loses the first KeyboardInterrupt, as a Cython module's initialisation inside
# SciPy's import did (numpy.random), and then goes on with a long run
SWALLOWING_COMMAND = """
    import sys, time
    import kinedyn.cli.commands.robots as command
    from kinedyn.cli import main

    def run(args):
        try:
            print("running", flush=True)  # inside the try: the test interrupts as soon as it reads this
            while True:
                time.sleep(0.02)
        except KeyboardInterrupt:
            print("swallowed", flush=True)
        {after}

    command.run = run
    sys.exit(main(["robots"]))
"""


def test_an_interrupt_a_library_swallows_is_delivered_again_and_the_cli_exits_130():
    proc = start(SWALLOWING_COMMAND.format(after="while True: time.sleep(0.02)"))
    wait_for_line(proc, "running")
    proc.send_signal(signal.SIGINT)
    out, err = finish(proc)
    assert proc.returncode == 130, (proc.returncode, out, err)
    assert "swallowed" in out and "Traceback" not in err and "KeyboardInterrupt" not in err, (out, err)


def test_work_that_never_returns_to_python_after_ctrl_c_still_ends_with_130():
    # every delivery swallowed (as by native work that never checks signals): the process exits by
    # itself once the interrupt has gone unanswered for kinedyn._ui.interrupts.GIVE_UP seconds
    proc = start(
        SWALLOWING_COMMAND.format(
            after="""
        while True:
            try:
                time.sleep(0.02)
            except KeyboardInterrupt:
                pass
        """.strip().replace("\n", "\n        ")
        )
    )
    wait_for_line(proc, "running")
    proc.send_signal(signal.SIGINT)
    out, err = finish(proc)
    assert proc.returncode == 130, (proc.returncode, out, err)
    assert "did not stop within" in err and "Traceback" not in err, err


def test_a_command_that_ends_on_ctrl_c_is_not_interrupted_again_while_it_closes():
    # the live viewer's pattern: Ctrl-C ends the wait, then a close that takes longer than a
    # redelivery interval, and the command's own status
    proc = start(
        """
        import sys, time
        import kinedyn.cli.commands.robots as command
        from kinedyn._ui import interrupts
        from kinedyn.cli import main

        def run(args):
            try:
                print("running", flush=True)  # inside the try, as above
                while True:
                    time.sleep(0.02)
            except KeyboardInterrupt:
                interrupts.taken()
            time.sleep(3 * interrupts.REDELIVER)
            print("closed", flush=True)
            return 0

        command.run = run
        sys.exit(main(["robots"]))
        """
    )
    wait_for_line(proc, "running")
    proc.send_signal(signal.SIGINT)
    out, err = finish(proc)
    assert proc.returncode == 0 and "closed" in out and "Traceback" not in err, (proc.returncode, out, err)


def test_a_long_native_simulation_stops_inside_its_loop_on_ctrl_c():
    # one native call of ~1e10 RK4 steps (hours): the child's own timer sends SIGINT to its main
    # thread 1 s after the call began; the call must end with KeyboardInterrupt, not run on
    proc = start(
        """
        import signal, threading, time
        import numpy as np
        import kinedyn as kd

        robot = kd.robots.get("planar_2r")
        steps = 10**10
        x0 = np.array([0.3, -0.2, 0.0, 0.0])
        print("running", flush=True)
        timer = threading.Timer(1.0, signal.pthread_kill, (threading.main_thread().ident, signal.SIGINT))
        start = time.monotonic()
        timer.start()
        try:
            kd.simulate(robot, steps * 1e-3, x0, method="rk4", dt=1e-3, record_every=steps, progress=False)
        except KeyboardInterrupt:
            print(f"interrupted after {time.monotonic() - start:.2f} s", flush=True)
        """
    )
    wait_for_line(proc, "running")
    out, err = finish(proc, timeout=120.0)
    assert proc.returncode == 0 and "interrupted after" in out, (proc.returncode, out, err)


def test_a_long_dynamics_batch_stops_between_its_chunks_on_ctrl_c():
    # one batch call of mass matrices (one rayon thread: about a second of work or more on any
    # machine), written into an out= array filled with NaN. A thread of the child sends SIGINT to
    # the process as soon as the first state's M appears: the call must end with KeyboardInterrupt
    # and leave states unwritten (the batch runner stopped between chunks), not finish the batch
    proc = start(
        """
        import os, signal, threading
        import numpy as np
        import kinedyn as kd
        from kinedyn.testing import random_robot

        robot = random_robot(1, n=30)
        q = np.random.default_rng(0).normal(size=(20000, robot.n))
        out = np.full((len(q), robot.n, robot.n), np.nan)
        call_ended = threading.Event()

        def interrupt_once_written():
            while np.isnan(out[0, 0, 0]) and not call_ended.is_set():
                call_ended.wait(0.001)
            os.kill(os.getpid(), signal.SIGINT)

        threading.Thread(target=interrupt_once_written, daemon=True).start()
        print("running", flush=True)
        try:
            robot.mass_matrix(q, out=out)
            call_ended.set()
            print("the call finished", flush=True)
        except KeyboardInterrupt:
            call_ended.set()
            unwritten = int(np.isnan(out).any(axis=(1, 2)).sum())
            print(f"interrupted with {unwritten} of {len(q)} states unwritten", flush=True)
        """,
        env={"RAYON_NUM_THREADS": "1"},
    )
    wait_for_line(proc, "running")
    out, err = finish(proc, timeout=120.0)
    assert proc.returncode == 0 and "interrupted with" in out, (proc.returncode, out, err)
    unwritten = int(out.split("interrupted with ")[1].split()[0])
    assert unwritten > 0, out


def test_the_command_line_exits_130_during_a_long_ik_batch():
    # a command (here a stand-in run of `kinedyn robots`) in one native IK call of a million
    # unreachable targets (hours: every restart is tried); SIGINT arrives 1 s into the call. The
    # command must exit 130 without a traceback because the call stopped, not because the CLI gave
    # the process up (kinedyn._ui.interrupts.GIVE_UP after 10 s, which says "did not stop within")
    proc = start(
        """
        import os, signal, sys, threading
        import numpy as np
        import kinedyn as kd
        import kinedyn.cli.commands.robots as command
        from kinedyn.cli import main

        def run(args):
            robot = kd.robots.get("ur5")
            targets = np.tile([5.0, 0.0, 0.0], (10**6, 1))
            threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT)).start()
            print("running", flush=True)
            robot.inverse_kinematics(targets, np.zeros(robot.n), method="numeric", progress=False)
            print("the call finished", flush=True)
            return 0

        command.run = run
        sys.exit(main(["robots"]))
        """
    )
    wait_for_line(proc, "running")
    out, err = finish(proc, timeout=120.0)
    assert proc.returncode == 130, (proc.returncode, out, err)
    assert "the call finished" not in out and "Traceback" not in err and "did not stop within" not in err, (out, err)
