"""Ctrl-C that always stops the command line.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread happens to be. When
that is inside a third-party import, the library may swallow it: a Cython module's initialisation
(numpy.random's, imported by SciPy) was seen to lose it, and the run then went on for hours after
Ctrl-C. :func:`sticky` makes an interrupt stick for the duration of a command: once SIGINT has
arrived, it is delivered again every :data:`REDELIVER` seconds until the command has unwound, and if
nothing unwinds within :data:`GIVE_UP` seconds (a native call that never returns to Python) the
process exits with status 130 without cleanup. Code that ends on Ctrl-C by design (the live viewer's
"Ctrl-C stops it") calls :func:`taken` so that its cleanup is not interrupted again.

A library user's process is left alone: only the command line installs this handler, and only over
Python's own default handler (a shell that started the command with SIGINT ignored keeps it so).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator

__all__ = ["sticky", "taken", "REDELIVER", "GIVE_UP", "EXIT_INTERRUPTED"]

REDELIVER = 0.5  # seconds between deliveries of an interrupt nothing has acted on yet
GIVE_UP = 10.0  # seconds after Ctrl-C after which the process exits without unwinding
EXIT_INTERRUPTED = 130  # 128 + SIGINT, the shell's status of a command stopped by Ctrl-C


class _State:
    def __init__(self) -> None:
        self.asked = threading.Event()  # SIGINT arrived
        self.done = threading.Event()  # the command unwound, or took the interrupt as its end
        self.lock = threading.Lock()  # a redelivery is never sent after `done` is set


_current: _State | None = None


def taken() -> None:
    """The running code has acted on Ctrl-C (it ends its work on it): no further delivery."""
    state = _current
    if state is not None:
        with state.lock:
            state.done.set()


def _redeliver(state: _State, main_ident: int) -> None:
    """Deliver SIGINT to the main thread again until the command unwinds; exit after GIVE_UP s."""
    waited = 0.0
    while not state.done.wait(REDELIVER):
        waited += REDELIVER
        if waited >= GIVE_UP:
            with contextlib.suppress(Exception):
                sys.stderr.write(f"kinedyn: interrupted (the work did not stop within {GIVE_UP:g} s of Ctrl-C)\n")
                sys.stderr.flush()
            os._exit(EXIT_INTERRUPTED)
        with state.lock:
            if state.done.is_set():
                return
            # to the main thread itself: a blocking system call there returns with EINTR
            signal.pthread_kill(main_ident, signal.SIGINT)


@contextlib.contextmanager
def sticky() -> Iterator[None]:
    """For the block (a command's run): SIGINT raises ``KeyboardInterrupt`` as usual and, until the
    block has unwound, again every REDELIVER seconds (module docstring). Does nothing outside the
    main thread or where SIGINT has a handler other than Python's default one."""
    global _current
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield
        return
    state = _State()
    main_ident = threading.main_thread().ident
    assert main_ident is not None

    def handler(signum, frame):
        if state.done.is_set():
            return
        if not state.asked.is_set():
            state.asked.set()
            threading.Thread(target=_redeliver, args=(state, main_ident), daemon=True, name="kinedyn-ctrl-c").start()
        raise KeyboardInterrupt

    previous, _current = _current, state
    signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        taken()
        _current = previous
        signal.signal(signal.SIGINT, signal.default_int_handler)
