"""What is wrong with a robot file, and what each tool would make of it (docs/audit.md).

:func:`audit` reads a URDF or MJCF file (or an XML string, or a :class:`Description`) and returns
an :class:`Audit`: one :class:`Finding` per problem, each naming the file, the line and the element
(``link 'x'``, ``joint 'j'``), with a severity and the fix. It sits in the description room: it
reads what a file says, before any robot is built, so it also reports files the loader refuses
(names used twice, links no joint connects) instead of stopping at the first.

Severities: ``error`` -- no rigid body or no reference reader accepts it (an inertia that is not
positive semi-definite, limits urdfdom refuses, a mimic cycle); ``warning`` -- legal, but implausible
or read differently by the tools (a rotated inertial frame MuJoCo drops, a density no material has, a
massless moving link); ``info`` -- what the audit could not measure.

The checks, and their sources:

- inertia: positive semi-definite principal moments and the triangle inequality ``I1 + I2 >= I3``
  (a rigid body's moments; Traversaro, Brossette, Escande & Nori, "Identification of fully physical
  consistent inertial parameters using optimization on manifolds", IROS 2016); the fix is the
  nearest consistent tensor of the repair policy (:meth:`Inertia.nearest_consistent`);
- mass against the link's own geometry (its collision shapes, else its visual ones, at uniform
  density: :mod:`kinedyn.description.audit_shapes`): the density (water 1000, aluminium 2700,
  steel 7850, tungsten 19300 kg/m^3), the centre of mass inside the shapes' convex hull, the
  inertia within a factor of ``INERTIA_FACTOR`` of the shape's (a factor near 1e6 or 1e9 says
  millimetres), meshes larger than a building (millimetres written as metres);
- massless moving links (MuJoCo refuses them, Genesis adds a tiny mass, the mass matrix is singular
  when nothing further out carries inertia); rotated inertial frames (``<inertial><origin rpy>``,
  which MuJoCo's URDF import dropped, mujoco#3559);
- joints: limits inverted, empty or missing (urdfdom refuses a revolute or prismatic joint without
  ``<limit>`` and a ``<limit>`` without effort or velocity), zero effort or velocity limits, mimic
  joints that follow an unknown, fixed or following joint, and mimic cycles;
- the tree: link and joint names used twice, joints naming links that do not exist, links with two
  parents, links no joint connects to the root, cycles.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass

import numpy as np

from .._math import rpy_to_matrix
from .audit_facts import REVOLUTE_OR_PRISMATIC, Facts, Finding, LinkFacts, description_facts, mjcf_facts, urdf_facts
from .audit_loops import loop_findings, source_kind
from .audit_shapes import Solid, combined, solid_of
from .description import Description
from .files import read_description
from .inertia import Inertia

__all__ = ["audit", "Audit", "Finding", "SEVERITIES", "INERTIA_FACTOR", "DENSITY_RANGE"]

SEVERITIES = ("error", "warning", "info")
#: densities [kg/m^3] outside which a link's mass for its shape is implausible: lighter than a
#: hollow plastic shell, denser than tungsten (19,300) with margin
DENSITY_RANGE = (50.0, 25_000.0)
#: a link's inertia more than this factor from its shape's at uniform density is implausible
INERTIA_FACTOR = 10.0
#: below this mass [kg] a moving link is "near-massless" (MuJoCo's mjMINVAL is 1e-15; simulators
#: stiffen well before it)
NEAR_MASSLESS = 1e-6


@dataclass
class Audit:
    """The findings of one robot file, errors first (then in file order)."""

    source: str
    findings: list

    @property
    def errors(self) -> list:
        return [f for f in self.findings if f.severity == "error"]

    @property
    def warnings(self) -> list:
        return [f for f in self.findings if f.severity == "warning"]

    @property
    def ok(self) -> bool:
        """No errors (warnings allowed)."""
        return not self.errors

    def counts(self) -> dict:
        return {s: sum(f.severity == s for f in self.findings) for s in SEVERITIES}

    def to_dict(self) -> dict:
        return {"source": self.source, "counts": self.counts(), "findings": [asdict(f) for f in self.findings]}

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, default=float)

    def __str__(self) -> str:
        c = self.counts()
        head = f"audit of {self.source}: {c['error']} errors, {c['warning']} warnings, {c['info']} notes"
        return "\n".join([head, *map(str, self.findings)])


# ============================================================================== the checks
def audit(source, *, geometry: bool = True) -> Audit:
    """The audit of a robot file (``.urdf``, ``.xml``/``.mjcf``), an XML string, or a
    :class:`Description` (see the module docstring). ``geometry=False`` skips the checks that read
    meshes and measure shapes."""
    if isinstance(source, Description):
        facts, kind = description_facts(source), "description"
        # the file it was read from says more (lines, what the loader drops); a xacro file is
        # expanded only on trust, so its description is audited as it is
        readable = os.path.splitext(source.source)[1].lower() in (".urdf", ".xml", ".mjcf")
        if readable and os.path.isfile(source.source):
            return audit(source.source, geometry=geometry)
    else:
        text = os.fspath(source) if isinstance(source, os.PathLike) else source
        if not isinstance(text, str):
            raise TypeError(f"audit expects a path, an XML string or a Description, got {type(source).__name__}")
        is_xml = "<" in text or "\n" in text
        if is_xml:
            kind = "mjcf" if "<mujoco" in text else "urdf"
            facts = mjcf_facts(text) if kind == "mjcf" else urdf_facts(text)
        else:
            ext = os.path.splitext(text)[1].lower()
            kind = source_kind(text)
            if ext == ".urdf":
                facts = urdf_facts(text)
            elif ext in (".xml", ".mjcf"):
                facts = mjcf_facts(text)
            else:
                # YAML/TOML robot files: through their description
                facts = description_facts(read_description(text))
    _check_tree(facts)
    _check_joints(facts)
    _check_links(facts, geometry)
    loop_findings(facts, source, kind)  # loops open at the file's reference configuration (audit_loops)
    order = {s: k for k, s in enumerate(SEVERITIES)}
    facts.findings.sort(key=lambda f: (order[f.severity], f.file, f.line or 0))
    return Audit(facts.source, facts.findings)


def _check_tree(facts: Facts) -> None:
    links: dict = {}
    for link in facts.links:
        if link.name in links:
            first = links[link.name]
            facts.add(
                "error",
                "name-twice",
                f"link '{link.name}'",
                link.file,
                link.line,
                f"the name is used twice (first at line {first.line}); every URDF reader refuses it",
                "rename one of the links",
            )
        links.setdefault(link.name, link)
    joints: dict = {}
    parent_of: dict = {}
    for j in facts.joints:
        what = f"joint '{j.name}'"
        if j.name in joints:
            facts.add(
                "error",
                "name-twice",
                what,
                j.file,
                j.line,
                f"the name is used twice (first at line {joints[j.name].line})",
                "rename one of the joints",
            )
        joints.setdefault(j.name, j)
        for end in (j.parent, j.child):
            if end not in links and end != facts.base:
                facts.add(
                    "error",
                    "unknown-link",
                    what,
                    j.file,
                    j.line,
                    f"names link '{end}', which is not defined",
                    f"define link '{end}' or correct the name",
                )
        if j.child in parent_of:
            facts.add(
                "error",
                "two-parents",
                f"link '{j.child}'",
                j.file,
                j.line,
                f"is the child of two joints, '{parent_of[j.child].name}' and '{j.name}' (a robot file describes a tree)",
                "keep one joint; a closed chain needs a constraint, not a second parent",
            )
        parent_of.setdefault(j.child, j)
    roots = [name for name in links if name not in parent_of]
    if len(roots) > 1:
        main = max(roots, key=lambda r: _subtree_size(r, facts))
        for r in roots:
            if r != main:
                link = links[r]
                facts.add(
                    "error",
                    "disconnected",
                    f"link '{r}'",
                    link.file,
                    link.line,
                    f"is connected to the root link '{main}' by no chain of joints",
                    f"add a joint from a link of the robot to '{r}', or remove it",
                )
    # cycles: follow parents from every link
    seen_cycle: set = set()
    for start in parent_of:
        path, link = [], start
        while link in parent_of and link not in path:
            path.append(link)
            link = parent_of[link].parent
        if link in path:
            cycle = frozenset(path[path.index(link) :])
            if cycle not in seen_cycle:
                seen_cycle.add(cycle)
                j = parent_of[link]
                facts.add(
                    "error",
                    "cycle",
                    f"joint '{j.name}'",
                    j.file,
                    j.line,
                    f"the joints form a cycle through links {sorted(cycle)}",
                    "break the cycle: a closed chain needs a loop constraint, not a joint",
                )


def _subtree_size(root: str, facts: Facts) -> int:
    children: dict = {}
    for j in facts.joints:
        children.setdefault(j.parent, []).append(j.child)
    count, stack, seen = 0, [root], set()
    while stack:
        n = stack.pop()
        if n in seen:
            continue
        seen.add(n)
        count += 1
        stack.extend(children.get(n, []))
    return count


def _check_joints(facts: Facts) -> None:
    by_name = {j.name: j for j in facts.joints}
    for j in facts.joints:
        what = f"joint '{j.name}'"
        moving = j.kind in (*REVOLUTE_OR_PRISMATIC, "continuous")
        limit = j.limit
        if j.kind in REVOLUTE_OR_PRISMATIC and j.checks_limits and limit is None:
            facts.add(
                "error",
                "limits-missing",
                what,
                j.file,
                j.line,
                f"a {j.kind} joint has no <limit> (urdfdom, so Pinocchio and ROS, refuse the file; kinedyn reads it unlimited)",
                '<limit lower="..." upper="..." effort="..." velocity="..."/>, or type="continuous" for an unlimited revolute joint',
            )
        if limit is not None and moving:
            line = limit.get("line", j.line)
            if j.checks_limits:
                absent = [k for k in ("effort", "velocity") if limit.get(k) is None]
                if absent:
                    facts.add(
                        "error",
                        "limits-incomplete",
                        what,
                        j.file,
                        line,
                        f"<limit> has no {' and no '.join(absent)} (urdfdom refuses it)",
                        f"give {' and '.join(absent)} (the actuator's rating)",
                    )
            lower, upper = limit.get("lower"), limit.get("upper")
            if j.kind in REVOLUTE_OR_PRISMATIC:
                lo = 0.0 if lower is None and j.checks_limits else lower
                hi = 0.0 if upper is None and j.checks_limits else upper
                if lo is not None and hi is not None:
                    if lo > hi:
                        facts.add(
                            "error",
                            "limits-inverted",
                            what,
                            j.file,
                            line,
                            f"lower limit {lo:g} is above upper limit {hi:g}"
                            + (" (an absent one is 0)" if None in (lower, upper) else "")
                            + "; no position satisfies them",
                            "swap them, or give the missing one",
                        )
                    elif lo == hi:
                        facts.add(
                            "warning",
                            "limits-empty",
                            what,
                            j.file,
                            line,
                            f"lower and upper limits are both {lo:g}: the joint cannot move"
                            + (" (an absent one is 0)" if None in (lower, upper) else ""),
                            "give the joint its range, or make it fixed",
                        )
            for k in ("effort", "velocity"):
                if limit.get(k) == 0:
                    facts.add(
                        "warning",
                        f"zero-{k}",
                        what,
                        j.file,
                        line,
                        f"its {k} limit is 0: a controller that honours it cannot move the joint",
                        f"give the actuator's {k} rating",
                    )
        if j.mimic is not None:
            leader_name, multiplier = j.mimic
            leader = by_name.get(leader_name)
            if leader is None:
                facts.add(
                    "error",
                    "mimic-unknown",
                    what,
                    j.file,
                    j.line,
                    f"mimics joint '{leader_name}', which is not defined",
                    "name an existing joint",
                )
            elif leader.kind == "fixed":
                facts.add(
                    "error",
                    "mimic-fixed",
                    what,
                    j.file,
                    j.line,
                    f"mimics the fixed joint '{leader_name}'",
                    "name a moving joint",
                )
            elif leader.mimic is not None:
                chain, seen = [j.name, leader_name], {j.name, leader_name}
                nxt = leader.mimic[0]
                while nxt in by_name and nxt not in seen:
                    chain.append(nxt)
                    seen.add(nxt)
                    nxt = by_name[nxt].mimic[0] if by_name[nxt].mimic else None
                if nxt in seen:
                    facts.add(
                        "error",
                        "mimic-cycle",
                        what,
                        j.file,
                        j.line,
                        f"mimic joints follow each other in a cycle ({' -> '.join(chain + [nxt])})",
                        "make one of them the independent leader",
                    )
                else:
                    facts.add(
                        "warning",
                        "mimic-chain",
                        what,
                        j.file,
                        j.line,
                        f"mimics '{leader_name}', which mimics another ({' -> '.join(chain)}); kinedyn composes the chain, other readers (Pinocchio, MuJoCo's equalities) expect one leader",
                        f"mimic '{chain[-1]}' directly with the composed multiplier and offset",
                    )
            if multiplier == 0:
                facts.add(
                    "warning",
                    "mimic-zero",
                    what,
                    j.file,
                    j.line,
                    "mimic multiplier 0: the joint follows nothing",
                    "remove the <mimic>, or make the joint fixed",
                )


def _moving_children(facts: Facts) -> dict:
    """link -> (is on a moving joint, mass of it and the links fixed to it)."""
    children: dict = {}
    for j in facts.joints:
        children.setdefault(j.parent, []).append(j)
    mass = {link.name: link.mass for link in facts.links}

    def rigid_mass(name, depth=0):
        total = mass.get(name, 0.0)
        for j in children.get(name, []):
            if j.kind == "fixed" and depth < 200:
                total += rigid_mass(j.child, depth + 1)
        return total

    return {j.child: rigid_mass(j.child) for j in facts.joints if j.kind not in ("fixed", "")}


def _check_links(facts: Facts, geometry: bool) -> None:
    moving = _moving_children(facts)
    cache: dict = {}
    for link in facts.links:
        what = f"link '{link.name}'"
        if link.mass < 0:
            facts.add(
                "error",
                "negative-mass",
                what,
                link.file,
                link.line,
                f"mass {link.mass:g} kg is negative",
                "give the link's mass",
            )
            continue
        if link.part_of_body:
            pass  # a massless link kinedyn makes between the joints of one MJCF body: MuJoCo's one body
        elif (
            link.name in moving
            and link.mass >= NEAR_MASSLESS
            and moving[link.name] == link.mass
            and not np.any(np.abs(link.tensor) > 1e-12 * link.mass)
        ):
            facts.add(
                "warning",
                "point-mass",
                what,
                link.file,
                link.line,
                f"moves on a joint with mass {link.mass:g} kg but no rotational inertia (a point mass): MuJoCo "
                "refuses it ('mass and inertia of moving bodies must be larger than mjMINVAL')",
                "give the link the inertia of its shape (a solid of its mass), or at least a small one",
            )
        elif link.name in moving and moving[link.name] < NEAR_MASSLESS:
            near = "massless" if moving[link.name] == 0 else f"near-massless ({moving[link.name]:.3g} kg)"
            facts.add(
                "warning",
                "massless",
                what,
                link.file,
                link.line,
                f"moves on a joint but is {near}: MuJoCo refuses a moving body without mass, Genesis gives it a tiny one, and the mass matrix is singular when nothing further out carries inertia about the joint",
                "give the link its mass and inertia (from CAD, or its shape at the material's density)",
            )
        _check_inertia(facts, link, what)
        if geometry and link.mass > 0:
            _check_geometry(facts, link, what, cache)


def _fmt_tensor(I: np.ndarray) -> str:
    # rounding noise of an eigen-decomposition (1e-17 beside 0.1) is written as the 0 it is
    I = np.where(np.abs(I) < 1e-12 * max(float(np.abs(I).max()), 1e-300), 0.0, I)
    return " ".join(
        f'{k}="{v:.6g}"'
        for k, v in zip(
            ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), (I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2])
        )
    )


def _check_inertia(facts: Facts, link: LinkFacts, what: str) -> None:
    if link.has_inertial and any(abs(a) > 1e-9 for a in link.rpy):
        fix = f'write the tensor in the link\'s axes: <origin rpy="0 0 0"> with <inertia {_fmt_tensor(link.tensor)}/>'
        facts.add(
            "warning",
            "rotated-inertia",
            what,
            link.file,
            link.line,
            f"its inertial frame is rotated (rpy {' '.join(f'{a:g}' for a in link.rpy)}): MuJoCo's URDF import dropped the rotation until mujoco#3559 was fixed, and tools differ on it",
            fix,
        )
    try:
        inertia = Inertia(link.mass, link.com, 0.5 * (link.tensor + link.tensor.T))
    except ValueError as e:  # a number beyond what a description may hold (the loader refuses it too)
        facts.add("error", "unreadable", what, link.file, link.line, f"its <inertial> cannot be read: {e}")
        return
    check = inertia.consistency()
    if check is None or check.ok:
        return
    repaired = np.array(inertia.nearest_consistent().inertia, dtype=float)
    # the fix in the frame the file writes the tensor in (the inertial origin's axes)
    R = np.array(rpy_to_matrix(*link.rpy), dtype=float)[:3, :3]
    in_file = R.T @ repaired @ R
    code = "inertia-not-positive" if not check.positive else "inertia-triangle"
    facts.add(
        "error",
        code,
        what,
        link.file,
        link.line,
        f"{check.describe()}: no rigid body has this inertia",
        f"the nearest consistent tensor (kinedyn's inertia='repair'): <inertia {_fmt_tensor(in_file)}/>",
        moments=list(check.moments),
        repaired=in_file.tolist(),
    )


def _check_geometry(facts: Facts, link: LinkFacts, what: str, cache: dict) -> None:
    for role in ("collision", "visual"):
        placed = [(s, where) for r, s, T, where in link.shapes if r == role for s in [solid_of(s, T, cache)]]
        if placed:
            break
    else:
        return
    unread = [(s, where) for s, where in placed if isinstance(s, str)]
    for reason, where in unread[:1]:
        file, _, line = where.rpartition(":")
        facts.add(
            "info",
            "mesh-not-read",
            what,
            file,
            int(line) if line.isdigit() else None,
            f"a {role} shape was {reason}; the checks against the link's geometry skip it",
        )
    solids = [s for s, _ in placed if isinstance(s, Solid)]
    if not solids:
        return
    if len(unread):
        return  # a link measured in part would read too light a shape
    shape = combined(solids)
    if not (math.isfinite(shape.volume) and shape.volume > 0 and np.all(np.isfinite(shape.points))):
        return  # sizes beyond measure (1e308 m): nothing to compare a mass with
    for s, where in placed:
        if isinstance(s, Solid) and s.extent > 0 and np.ptp(s.points, axis=0).max() > 20.0:
            file, _, line = where.rpartition(":")
            facts.add(
                "warning",
                "units-mesh",
                what,
                file,
                int(line) if line.isdigit() else None,
                f"a {role} shape is {np.ptp(s.points, axis=0).max():.4g} m across: a mesh in millimetres read as metres",
                'scale the mesh: <mesh ... scale="0.001 0.001 0.001"/>',
            )
    density = link.mass / shape.volume
    lo, hi = DENSITY_RANGE
    if not lo <= density <= hi:
        hint = ""
        if density < 1e-3:
            hint = " (a shape 1000 times too large: millimetres read as metres?)"
        elif density > 1e6:
            hint = " (a mass in grams, or a shape 1000 times too small?)"
        facts.add(
            "warning",
            "density",
            what,
            link.file,
            link.line,
            f"mass {link.mass:.4g} kg in the {shape.volume:.4g} m^3 of its {role} shape{'s' if len(solids) > 1 else ''} is {density:.4g} kg/m^3, outside {lo:g}..{hi:g}{hint}",
            f"check the mass and the shape's units; at 2700 kg/m^3 (aluminium) the shape weighs {2700 * shape.volume:.4g} kg",
            density=density,
            volume=shape.volume,
        )
    # the centre of mass inside the convex hull of the shapes (with a margin of 5 % of their size)
    size = float(np.ptp(shape.points, axis=0).max())
    if size > 0 and not _inside_hull(link.com, shape.points, 0.05 * size):
        facts.add(
            "warning",
            "com-outside",
            what,
            link.file,
            link.line,
            f"its centre of mass ({' '.join(f'{c:.4g}' for c in link.com)}) m lies outside its {role} shape (the hull spans {' '.join(f'{a:.4g}..{b:.4g}' for a, b in zip(shape.points.min(0), shape.points.max(0)))} m)",
            f"check the <inertial><origin xyz>; the shape's centre at uniform density is {' '.join(f'{c:.4g}' for c in shape.centre)}",
        )
    expected = link.mass / shape.volume * shape.moments
    ratio = float(np.trace(link.tensor) / np.trace(expected)) if np.trace(expected) > 0 else math.nan
    if math.isfinite(ratio) and ratio > 0 and not 1 / INERTIA_FACTOR <= ratio <= INERTIA_FACTOR:
        units = ""
        if 1e5 < ratio < 1e7:
            units = " (about 1e6: kg mm^2 written as kg m^2?)"
        elif 1e8 < ratio < 1e10:
            units = " (about 1e9: g mm^2 or a mesh in mm?)"
        facts.add(
            "warning",
            "inertia-vs-shape",
            what,
            link.file,
            link.line,
            f"its inertia is {ratio:.3g} times that of its {role} shape at uniform density with the same mass{units}",
            f"compare with the shape's: <inertia {_fmt_tensor(expected)}/> (about the shape's centre)",
            ratio=ratio,
        )


def _inside_hull(point: np.ndarray, points: np.ndarray, margin: float) -> bool:
    """Whether ``point`` lies within ``margin`` of the convex hull of ``points``."""
    lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
    if np.any(point < lo) or np.any(point > hi):
        return False
    try:
        from scipy.spatial import ConvexHull  # only here: SciPy's import is slow and most calls stop above

        hull = ConvexHull(points)
    except Exception:  # flat or degenerate point sets: the box test above is all there is  # noqa: BLE001
        return True
    return bool(np.all(hull.equations[:, :3] @ point + hull.equations[:, 3] <= margin))
