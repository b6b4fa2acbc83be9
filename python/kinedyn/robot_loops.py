"""The closed-loop half of the ``Robot`` facade: the loops a robot declares and the methods that
respect them (docs/architecture.md, the layers). ``Robot`` inherits :class:`ClosedLoops`; each method
here is a one-line forward to the capability that does the work, as in ``kinedyn.robot``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .description.loops import Loop

if TYPE_CHECKING:
    from .description.description import Description
    from .robot import Robot

__all__ = ["ClosedLoops"]


class ClosedLoops:
    """Closed kinematic loops of a robot (LaValle 13.4): constraints between two frames of its tree."""

    @property
    def loops(self) -> tuple:
        """The robot's closed loops (:class:`~kinedyn.description.loops.Loop`: name, the two frames,
        kind, ``rows``); empty for a tree."""
        return self.description.loops

    description: Description  # the Robot's own (kinedyn.robot)

    def add_loop(self, frame_a: str, frame_b: str, kind: str = "point", name: str | None = None) -> Robot:
        """A new robot with a loop closing ``frame_a`` on ``frame_b``: ``kind="point"`` makes their
        origins coincide (3 rows), ``"weld"`` the frames whole (6 rows). ``name`` defaults to
        ``"loop<k>"``."""
        if name is None:
            taken = {loop.name for loop in self.loops}
            name = next(f"loop{k}" for k in range(len(taken) + 1) if f"loop{k}" not in taken)
        return self.replace(loops=self.loops + (Loop(name, frame_a, frame_b, kind),))  # type: ignore[attr-defined]
