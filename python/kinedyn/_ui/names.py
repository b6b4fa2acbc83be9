"""A "did you mean" for a misspelt name (a joint, a frame, a parameter): the closest names by
difflib's ratio (Python's standard library, ``difflib.get_close_matches``)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = ["did_you_mean"]


def did_you_mean(name: object, choices: Iterable[object]) -> str:
    """``"; did you mean 'elbow_joint'?"`` (or two names) when ``name`` is close to some of
    ``choices``; ``""`` when none is (a message then lists the choices itself)."""
    names = [str(c) for c in choices]
    close = difflib.get_close_matches(str(name), names, n=2, cutoff=0.6)
    if not close:  # a different case only ('Shoulder' for 'shoulder')
        close = [c for c in names if c.lower() == str(name).lower()][:2]
    if not close:
        return ""
    return "; did you mean " + " or ".join(f"'{c}'" for c in close) + "?"
