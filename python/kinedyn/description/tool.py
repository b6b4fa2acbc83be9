"""The default tool frame of a robot description: which link ``robot.tool`` names when the user names none.

A branching description (an arm with a two-finger gripper, a humanoid) has several ends; the one a
user means by "the tool" is, in this order of preference:

1. a link the description names as its tool, by the conventions of ROS description packages
   (REP 199 names ``tool0`` and ``flange``; MoveIt configurations use ``*_tcp``, ``ee_link``,
   ``*_hand``): see :data:`TOOL_NAMES` -- the better-ranked name pattern first, then the link with
   more moving joints between it and the base, then the later link in the description;
2. otherwise the end of the longest chain: the link carried by the deepest moving joint (the one
   with the most moving joints on its path to the base; of equal ones, the later in the description),
   and of the links it carries (through fixed joints), the later in the description (e.g. a fixed
   ``tool0`` after the last link of a serial arm).

Only links that move with at least one joint qualify. The search is one pass over the links plus
a regular-expression match per link name.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

__all__ = ["TOOL_NAMES", "default_tool"]

#: Link-name patterns (full match, case-insensitive) that name a tool frame, best first.
TOOL_NAMES = (
    r"tcp|tool0|tool|ee_link|end_effector|ee|flange",  # the whole name says it
    r".*[_-](tcp|tool0|tool_link|ee_link|end_effector|ee|flange)",  # panda_hand_tcp, arm_tool0, gripper_ee
    r".*[_-]hand|hand",  # panda_hand
    r".*tool.*",  # wrist_right_ft_tool_link
)
_PATTERNS = [re.compile(p, re.IGNORECASE) for p in TOOL_NAMES]


def _rank(name: str) -> int | None:
    for rank, pattern in enumerate(_PATTERNS):
        if pattern.fullmatch(name):
            return rank
    return None


def default_tool(links: Sequence, base: str) -> str:
    """The default tool frame (see the module docstring) of ``links`` (objects with ``name``,
    ``parent`` and ``joint.is_moving``; any order, parents need not come first) rooted at ``base``."""
    parent = {link.name: link.parent for link in links}
    moving = {link.name: bool(link.joint.is_moving) for link in links}
    depth: dict[str, int] = {base: 0}  # moving joints between the base and the link
    carrier: dict[str, str | None] = {base: None}  # the nearest moving link at or above the link

    def resolve(name: str) -> None:
        path = []
        while name not in depth:
            path.append(name)
            name = parent.get(name) or base  # build_tree reports a broken tree; here it is cut at the base
            if len(path) > len(parent) + 1:
                break
        for child in reversed(path):
            up = parent.get(child) or base
            up = up if up in depth else base
            depth[child] = depth[up] + moving[child]
            carrier[child] = child if moving[child] else carrier[up]

    for link in links:
        resolve(link.name)
    order = {link.name: k for k, link in enumerate(links)}
    candidates = [link.name for link in links if carrier[link.name] is not None]
    if not candidates:
        return base
    named = [(r, name) for name in candidates if (r := _rank(name)) is not None]
    if named:
        best = min(r for r, _ in named)
        return max((name for r, name in named if r == best), key=lambda name: (depth[name], order[name]))
    deepest = max((name for name in candidates if moving[name]), key=lambda name: (depth[name], order[name]))
    return max((name for name in candidates if carrier[name] == deepest), key=lambda name: order[name])
