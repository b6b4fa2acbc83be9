"""Progress for long work on a terminal: a rich progress bar on stderr, shown only when stderr is a
terminal (or when asked), never on stdout, transient (it disappears when the work is done).

``Steps`` counts named steps (the report's sections, the tutorial's questions); the simulation has
its own bar over simulated time (``kinedyn.simulate.core``)."""

from __future__ import annotations

import sys
from typing import Optional

__all__ = ["Steps", "wanted"]


def wanted(progress: Optional[bool]) -> bool:
    """``progress`` as given, or (None) whether stderr is a terminal."""
    if progress is None:
        return bool(getattr(sys.stderr, "isatty", lambda: False)())
    return bool(progress)


class Steps:
    """``with Steps("report", total=5, progress=None) as p: p.step("simulation"); ...``: a bar of
    ``total`` named steps on stderr; does nothing when progress is off."""

    def __init__(self, label: str, total: int, progress: Optional[bool] = None):
        self.label = label
        self.total = max(int(total), 1)
        self.bar = None
        self.task = None
        if wanted(progress):
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(TextColumn(f"{label}:"), TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                                console=Console(file=sys.stderr), transient=True)
            self.task = self.bar.add_task("", total=self.total)
            self.bar.start()

    def step(self, description: str) -> None:
        """Start the named step (the previous one is done)."""
        if self.bar is not None:
            done = self.bar.tasks[0].completed
            if self.bar.tasks[0].description:
                done += 1
            self.bar.update(self.task, description=description, completed=min(done, self.total))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.update(self.task, completed=self.total)
            self.bar.stop()
            self.bar = None

    def __enter__(self) -> "Steps":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
