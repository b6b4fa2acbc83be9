"""Progress for long work on a terminal: a rich progress bar on stderr, shown only when stderr is a
terminal (or when asked), never on stdout, transient (it disappears when the work is done).

``Steps`` counts named steps (the report's sections, the tutorial's questions); ``Delayed`` is a bar
over an amount of work (simulated time, targets of a batch) that appears only once the work has
taken ``delay`` seconds, so that short runs stay silent.

``import kinedyn`` loads this module (the simulator and IK report progress through it), so rich
(about 65 ms to import) is imported only where a bar or spinner is drawn."""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.progress import Progress, TaskID

__all__ = ["Steps", "Delayed", "busy", "wanted"]

SHOW_AFTER = 1.0  # seconds: work that runs longer shows a bar (so runs over ~2 s show progress)


def wanted(progress: bool | None) -> bool:
    """``progress`` as given, or (None) whether stderr is a terminal."""
    if progress is None:
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress)


class Steps:
    """``with Steps("report", total=5, progress=None) as p: p.step("simulation"); ...``: a bar of
    ``total`` named steps on stderr; does nothing when progress is off."""

    def __init__(self, label: str, total: int, progress: bool | None = None):
        self.label = label
        self.total = max(int(total), 1)
        self.bar: Progress | None = None
        self.task: TaskID | None = None
        if wanted(progress):  # rich loads only when a bar is drawn (module docstring)
            from rich.console import Console
            from rich.markup import escape
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(
                TextColumn(f"{escape(label)}:"),
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(file=sys.stderr),
                transient=True,
            )
            self.task = self.bar.add_task("", total=self.total)
            self.bar.start()

    def step(self, description: str) -> None:
        """Start the named step (the previous one is done)."""
        if self.bar is not None and self.task is not None:
            done = self.bar.tasks[0].completed
            if self.bar.tasks[0].description:
                done += 1
            from rich.markup import escape  # rich: only with a bar (module docstring)

            self.bar.update(self.task, description=escape(description), completed=min(done, self.total))

    def close(self) -> None:
        if self.bar is not None and self.task is not None:
            self.bar.update(self.task, completed=self.total)
            self.bar.stop()
            self.bar = None

    def __enter__(self) -> Steps:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Delayed:
    """A bar over ``total`` units of work on stderr, shown once the work has run ``delay`` seconds
    (at once for ``delay=0``); ``text`` formats the amount (rich's ``{task.completed}``,
    ``{task.total}``). Does nothing when ``enabled`` is false."""

    def __init__(
        self,
        enabled: bool,
        total: float,
        label: str,
        text: str = "{task.completed:.0f} / {task.total:.0f}",
        delay: float = 0.0,
    ):
        self.enabled, self.total, self.label, self.text, self.delay = enabled, total, label, text, delay
        self.bar: Progress | None = None
        self.task: TaskID | None = None
        self.start = time.perf_counter()
        self.last = 0.0
        if enabled and delay <= 0:
            self._show()

    def _show(self) -> None:
        # rich loads only when a bar is drawn (module docstring)
        from rich.console import Console
        from rich.markup import escape
        from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

        bar = Progress(
            TextColumn(escape(self.label)),
            BarColumn(),
            TextColumn(self.text),
            TimeRemainingColumn(),
            console=Console(file=sys.stderr),
            transient=True,
        )
        self.bar, self.task = bar, bar.add_task(self.label, total=self.total)
        bar.start()

    def update(self, done: float) -> None:
        """``done`` units of the total are finished."""
        if not self.enabled:
            return
        now = time.perf_counter()
        if self.bar is None:
            if now - self.start < self.delay or done >= self.total:
                return
            self._show()
        if self.bar is not None and self.task is not None and (now - self.last > 0.05 or done >= self.total):
            self.bar.update(self.task, completed=min(done, self.total))
            self.last = now

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


@contextlib.contextmanager
def busy(label: str, progress: bool | None = None) -> Iterator[None]:
    """A spinner with ``label`` and the elapsed time on stderr while the block runs (for work that
    cannot report its own progress, such as a SymPy derivation); nothing when progress is off."""
    if not wanted(progress):
        yield
        return
    from rich.console import Console  # rich loads only when a spinner is drawn (module docstring)
    from rich.markup import escape

    with Console(file=sys.stderr).status(escape(label)):
        yield
