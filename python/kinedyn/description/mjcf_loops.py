"""MJCF ``<equality><connect>`` and ``<weld>`` read as closed loops (:mod:`kinedyn.description.loops`).

MuJoCo's XML reference ("equality/connect", "equality/weld") and its compiler (``mj_setConst``,
which fills ``eq_data`` at ``qpos0``) define what each form holds; each becomes a
:class:`~kinedyn.description.loops.Loop` between two frames, adding a frame where the file names a
point on a body rather than a site:

- ``<connect body1 anchor [body2]>``: the point ``anchor`` of body1 (in its frame) and the point of
  body2 (the world when omitted) where that anchor lies at ``qpos0`` coincide: frames
  ``<loop>_a`` on body1 at ``anchor`` and ``<loop>_b`` on body2 at
  ``inv(X_body2(qpos0)) X_body1(qpos0) anchor``; a point loop.
- ``<connect site1 site2>``: the two sites' origins coincide, wherever they are at ``qpos0``.
- ``<weld body1 [body2] [anchor] [relpose]>``: body2's point ``anchor`` (its frame) and body2's axes
  stay where ``relpose`` (position in body1's frame, then the quaternion of body2's axes in body1's)
  puts them; a relpose whose quaternion is zero (MuJoCo's default) means "as at ``qpos0``":
  frames ``<loop>_b`` on body2 at ``anchor`` and ``<loop>_a`` on body1 at
  ``(relpose position, relpose rotation)``, or at ``inv(X_body1(qpos0)) X_body2(qpos0) Tr(anchor)``;
  a weld loop. ``torquescale="0"`` drops the rotation rows (MuJoCo: "behaves like a connect"), so
  it is read as a point loop.
- ``<weld site1 site2>``: the two sites' frames coincide.

``qpos0`` is MuJoCo's reference configuration: every hinge and slide at its ``ref`` (kinedyn's
``q = qpos``, so there the joint moves nothing), ball joints at the identity, free bodies where the
file puts them. Not modelled, and named in the loader's warning: MuJoCo's softness of every
equality (``solref``, ``solimp``: kinedyn holds a loop exactly), a weld's ``torquescale`` other than
0 or 1 (a weighting of the soft rows), inactive equalities (``active="false"``, also from a
``<default><equality>`` class: not read), and the equalities of tendons and flexes.
"""

from __future__ import annotations

import numpy as np

from .._math import pose_inverse
from .._ui.names import did_you_mean
from .link import Frame
from .loop_files import unique_name
from .loops import Loop
from .mjcf_xml import numbers, pose, quat_matrix, short, translation_of

__all__ = ["equality_loops"]


def equality_loops(reader) -> tuple:
    """``(frames, loops)``: the frames added at the anchors and the loops of the model's
    ``<connect>`` and ``<weld>`` equalities; ``reader`` is the MJCF reader after its ``read()``
    (its sources, root, body reference poses, site frames, frame names and ignored notes)."""
    src, frames, loops = reader.src, [], []
    taken = set(reader.names) | {f.name for f in reader.frames}
    loop_names: set = set()
    soft = 0
    index = -1  # MuJoCo numbers the equalities of every kind in file order
    for section in reader.root.iterfind("equality"):
        for element in section:
            index += 1
            if element.tag not in ("connect", "weld"):
                continue
            a = _attributes(reader, element)
            name = a.get("name") or f"equality{index}"
            what = f"{element.tag} '{name}'"
            if a.get("active", "true") not in ("true", "false"):
                raise src.error(element, f"attribute 'active' must be true or false, got '{short(a['active'])}'")
            if a.get("active", "true") == "false":
                reader.ignored.add(f"the inactive <equality><{what}> (active='false'): not read as a loop")
                continue
            if name in loop_names:
                raise src.error(element, f"the name '{name}' is given to two <equality> elements")
            loop_names.add(name)
            kind = "weld" if element.tag == "weld" else "point"
            if element.tag == "weld":
                scale = numbers(element, "torquescale", src, 1, text=a.get("torquescale", "1"))[0]
                if scale == 0:
                    kind = "point"  # MuJoCo: the rotation rows vanish, "a weld behaves like a connect"
                elif scale != 1:
                    reader.ignored.add(
                        f"torquescale='{short(a['torquescale'])}' of the <{what}> (a weighting of soft rows)"
                    )
            site_form = "body1" not in a or (element.tag == "connect" and "anchor" not in a)
            if site_form:
                frame_a, frame_b = _site_frames(reader, element, a, what)
            else:
                placed = _body_frames(reader, element, a, what)
                frame_a, frame_b = (unique_name(f"{name}_{end}", taken) for end in "ab")
                frames += [Frame(frame_a, placed[0][0], placed[0][1]), Frame(frame_b, placed[1][0], placed[1][1])]
            try:
                loops.append(Loop(name, frame_a, frame_b, kind))
            except ValueError as e:
                raise src.error(element, str(e)) from None
            soft += 1
    if soft:
        reader.ignored.add(
            f"the softness of {soft} <equality> loop{'s' if soft > 1 else ''} (MuJoCo's solref/solimp; "
            "kinedyn holds a loop exactly)"
        )
    return frames, loops


def _attributes(reader, element) -> dict:
    """The equality's attributes over its ``<default><equality>`` class's (MuJoCo's defaults hold
    the attributes every equality shares: active, solref, solimp)."""
    cls = element.get("class") or "main"
    if cls not in reader.defaults and cls != "main":
        raise reader.src.error(element, f"class='{cls}' names no <default> class")
    out = dict(reader.defaults.get(cls, {}).get("equality", {}))
    out.update(element.attrib)
    return out


def _site_frames(reader, element, a: dict, what: str) -> tuple:
    src = reader.src
    if "site1" not in a or "site2" not in a:
        needs = "body1 and anchor, or site1 and site2" if element.tag == "connect" else "body1, or site1 and site2"
        raise src.error(element, f"{what}: needs {needs}")
    out = []
    for key in ("site1", "site2"):
        site = a[key]
        if site not in reader.site_frames:
            known = list(reader.site_frames)
            raise src.error(element, f"{what}: {key}='{short(site)}' names no <site>{did_you_mean(site, known)}")
        out.append(reader.site_frames[site])
    return tuple(out)


def _body(reader, element, a: dict, key: str, what: str) -> str:
    body = a.get(key, "world")
    if body != "world" and body not in reader.scopes["body"]:
        known = ["world", *reader.scopes["body"]]
        raise reader.src.error(element, f"{what}: {key}='{short(body)}' names no <body>{did_you_mean(body, known)}")
    return body


def _body_frames(reader, element, a: dict, what: str) -> tuple:
    """((link of frame a, its placement), (link of frame b, its placement)) of a body-form equality."""
    src = reader.src
    body1, body2 = _body(reader, element, a, "body1", what), _body(reader, element, a, "body2", what)
    if body1 == body2:
        raise src.error(element, f"{what}: body1 and body2 are both '{body1}'")
    X1, X2 = reader.reference[body1], reader.reference[body2]  # world poses at qpos0
    link1, link2 = (None if b == "world" else b for b in (body1, body2))
    if element.tag == "connect":
        anchor = translation_of(numbers(element, "anchor", src, 3, text=a["anchor"]))
        at_b = (_inverse(X2) @ X1 @ anchor)[:3, 3]  # the anchor in body2's frame at qpos0
        return (link1, anchor), (link2, translation_of(at_b[:3]))
    anchor = translation_of(numbers(element, "anchor", src, 3, text=a.get("anchor", "0 0 0")))
    relpose = numbers(element, "relpose", src, 7, text=a.get("relpose", "0 1 0 0 0 0 0"))
    quat = np.array(relpose[3:])
    if np.linalg.norm(quat) == 0:  # MuJoCo's default: the relative pose at qpos0
        placement = _inverse(X1) @ X2 @ anchor
    else:
        placement = pose(relpose[:3], quat_matrix(*(quat / np.linalg.norm(quat))))
    return (link1, placement), (link2, anchor)


def _inverse(X) -> np.ndarray:
    return np.asarray(pose_inverse(X), dtype=float)
