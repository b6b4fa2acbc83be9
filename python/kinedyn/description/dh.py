"""Denavit-Hartenberg tables -> links.

Conventions (docs/conventions.md):
- ``"standard"`` (Spong, Corke): A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i); joint i moves about
  / along z_{i-1}; link frame i is DH frame i (at the far end of link i).
- ``"modified"`` (Craig): A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); each row holds
  (alpha_{i-1}, a_{i-1}, theta_i, d_i); link frame i sits on joint i's axis.
For a revolute joint ``theta`` is the joint offset (joint angle = q + theta); for a prismatic joint
``d`` is (joint displacement = q + d). Inertias are given in link frame i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any, Optional

import sympy as sp

from .._math import matmul, rot_x, rot_z, translation
from .checks import number
from .inertia import Inertia
from .joint import Joint
from .link import Link

__all__ = ["DHRow", "links_from_dh"]


@dataclass(frozen=True)
class DHRow:
    theta: Any = 0.0
    d: Any = 0.0
    a: Any = 0.0
    alpha: Any = 0.0
    kind: str = "revolute"
    name: Optional[str] = None
    inertia: Inertia = field(default_factory=Inertia)
    lower: float = -math.inf
    upper: float = math.inf
    velocity_limit: float = math.inf
    effort_limit: float = math.inf
    gear_ratio: Any = 1.0
    rotor_inertia: Any = 0.0
    viscous: Any = 0.0
    coulomb: Any = 0.0  # one level, or (positive, negative) levels: see Joint
    coulomb_negative: Any = None

    def __post_init__(self):
        # coulomb=(positive, negative) is stored as the two fields, as Joint stores it
        if isinstance(self.coulomb, (tuple, list)):
            if len(self.coulomb) != 2 or self.coulomb_negative is not None:
                raise ValueError(f"DH row '{self.name}': coulomb must be one level or a pair (positive, negative), given once; got {self.coulomb!r}")
            object.__setattr__(self, "coulomb_negative", self.coulomb[1])
            object.__setattr__(self, "coulomb", self.coulomb[0])

    @classmethod
    def from_mapping(cls, row: dict, index: int) -> "DHRow":
        known = {f.name for f in fields(cls)}
        row = dict(row)
        if "type" in row:
            row["kind"] = row.pop("type")
        if "qlim" in row:
            row["lower"], row["upper"] = row.pop("qlim")
        if "offset" in row:  # an explicit joint offset adds to theta (revolute) or d (prismatic)
            off = row.pop("offset")
            key = "d" if row.get("kind", "revolute") == "prismatic" else "theta"
            row[key] = row.get(key, 0.0) + off
        unknown = set(row) - known
        if unknown:
            raise ValueError(f"DH row {index + 1}: unknown keys {sorted(unknown)} (known: {sorted(known)})")
        return cls(**row)


def _row(row, index: int) -> DHRow:
    if isinstance(row, DHRow):
        return row
    if isinstance(row, dict):
        return DHRow.from_mapping(row, index)
    values = list(row)
    if len(values) not in (4, 5):
        raise ValueError(
            f"DH row {index + 1}: expected (theta, d, a, alpha[, kind]) or a mapping, got {len(values)} values"
        )
    return DHRow(*values)


def links_from_dh(rows, convention: str = "standard"):
    """One Link per DH row; joint i is named ``q{i}`` unless the row names it."""
    if convention not in ("standard", "modified"):
        raise ValueError(f"DH convention must be 'standard' or 'modified', got '{convention}'")
    rows = [_row(r, i) for i, r in enumerate(rows)]
    if not rows:
        raise ValueError("a DH table needs at least one row")
    links = []
    parent = None
    for i, r in enumerate(rows, start=1):
        if r.kind not in ("revolute", "prismatic"):
            raise ValueError(f"DH row {i}: kind must be 'revolute' or 'prismatic', got '{r.kind}'")
        # real, finite, sane numbers (or symbols) before they enter the transforms; exact SymPy
        # numbers (pi / 2) stay exact, so symbolic DH robots keep their exact zeros
        checked = {key: number(getattr(r, key), f"DH row {i}: {key}") for key in ("theta", "d", "a", "alpha")}
        r = replace(r, **{k: v for k, v in checked.items() if not isinstance(getattr(r, k), sp.Basic)})
        revolute = r.kind == "revolute"
        joint = Joint(
            name=r.name or f"q{i}",
            kind=r.kind,
            axis=(0.0, 0.0, 1.0),
            offset=r.theta if revolute else r.d,
            lower=r.lower,
            upper=r.upper,
            velocity_limit=r.velocity_limit,
            effort_limit=r.effort_limit,
            gear_ratio=r.gear_ratio,
            rotor_inertia=r.rotor_inertia,
            viscous=r.viscous,
            coulomb=r.coulomb,
            coulomb_negative=r.coulomb_negative,
        )
        if convention == "standard":
            # Rz(theta) Tz(d) | Tx(a) Rx(alpha): the joint moves first, the rest is fixed to link i
            placement = translation(0, 0, 0) if revolute else rot_z(r.theta)
            post = matmul(translation(0, 0, r.d), translation(r.a, 0, 0), rot_x(r.alpha)) if revolute else matmul(
                translation(r.a, 0, 0), rot_x(r.alpha)
            )
        else:
            # Rx(alpha_{i-1}) Tx(a_{i-1}) | Rz(theta_i) Tz(d_i): fixed part first, then the joint
            placement = matmul(rot_x(r.alpha), translation(r.a, 0, 0), translation(0, 0, r.d) if revolute else rot_z(r.theta))
            post = translation(0, 0, 0)
        name = f"link{i}"
        links.append(Link(name, parent, joint, placement, post, r.inertia))
        parent = name
    return links, rows
