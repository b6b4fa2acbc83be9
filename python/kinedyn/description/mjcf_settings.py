"""Model-wide settings of an MJCF file: ``<compiler>``, ``<option>`` and the ``<default>`` classes
(MuJoCo's "XML Reference"), read before the bodies by :mod:`kinedyn.description.mjcf`.

``<option>``, every attribute (MuJoCo 3): ``gravity`` is read, and ``<flag gravity="disable">``;
``<flag damper="disable">`` (older MuJoCo: ``passive``) drops the joints' damping and
``<flag frictionloss="disable">`` (or ``constraint="disable"``) their dry friction, as MuJoCo does.
``density``, ``viscosity`` and ``wind`` switch on MuJoCo's fluid forces (its inertia-box or
ellipsoid model), which kinedyn does not model: they are named in the loader's "does not model"
warning, as is an ``<option><plugin>``. The rest are numerics of MuJoCo's integrator, solver and
contacts, which change no term of the equations of motion kinedyn computes, and are skipped:
``timestep``, ``apirate``, ``impratio``, ``tolerance``, ``ls_tolerance``, ``noslip_tolerance``,
``ccd_tolerance``, ``magnetic`` (read by magnetometers only), ``o_margin``, ``o_solref``,
``o_solimp``, ``o_friction``, ``integrator``, ``cone``, ``jacobian``, ``solver``, the
``*iterations`` counts, ``sdf_initpoints``, ``actuatorgroupdisable`` and the other flags.
"""

from __future__ import annotations

import os
from typing import Any

from .mjcf_xml import Sources, numbers, short

__all__ = ["ModelSettings", "DEFAULTED", "FLUID_OPTIONS"]

#: the elements whose <default> attributes kinedyn reads
DEFAULTED = ("joint", "geom", "site", "mesh", "equality")
#: <option> attributes that switch on MuJoCo's fluid forces (its XML reference, "option")
FLUID_OPTIONS = ("density", "viscosity", "wind")


class ModelSettings:
    """The compiler settings, the option's gravity and flags, and the default classes of a model."""

    src: Sources
    root: Any  # the model's root element (xml.etree)
    ignored: set
    defaults: dict

    def compiler(self) -> None:
        self.degrees, self.eulerseq, self.autolimits = True, "xyz", True
        self.inertiafromgeom, self.groups = "auto", (0, 5)
        # MuJoCo's compiler adjustments of body inertias (off by default)
        self.boundmass, self.boundinertia, self.settotalmass, self.balanceinertia = 0.0, 0.0, -1.0, False
        self.meshdir = self.src.base_dir
        for c in self.root.iter("compiler"):
            for attribute, value in c.attrib.items():
                if attribute == "angle":
                    if value not in ("degree", "radian"):
                        raise self.src.error(c, f"attribute 'angle' must be 'degree' or 'radian', got '{short(value)}'")
                    self.degrees = value == "degree"
                elif attribute == "eulerseq":
                    if len(value) != 3 or any(ch not in "xyzXYZ" for ch in value):
                        raise self.src.error(
                            c, f"attribute 'eulerseq' must be 3 letters of xyz or XYZ, got '{short(value)}'"
                        )
                    self.eulerseq = value
                elif attribute == "autolimits":
                    self.autolimits = self.boolean(c, attribute, value)
                elif attribute == "inertiafromgeom":
                    if value not in ("true", "false", "auto"):
                        raise self.src.error(
                            c, f"attribute 'inertiafromgeom' must be true, false or auto, got '{short(value)}'"
                        )
                    self.inertiafromgeom = value
                elif attribute == "inertiagrouprange":
                    lo, hi = numbers(c, attribute, self.src, 2)
                    self.groups = (int(lo), int(hi))
                elif attribute in ("meshdir", "assetdir"):
                    if self.src.base_dir is not None and (attribute == "meshdir" or c.get("meshdir") is None):
                        self.meshdir = os.path.join(self.src.base_dir, value)
                elif attribute == "coordinate" and value != "local":
                    raise self.src.error(
                        c, f"coordinate='{value}': only local coordinates are read (MuJoCo removed global ones)"
                    )
                elif attribute in ("boundmass", "boundinertia", "settotalmass"):
                    setattr(self, attribute, numbers(c, attribute, self.src, 1)[0])
                elif attribute == "balanceinertia":
                    self.balanceinertia = self.boolean(c, attribute, value)
                elif attribute == "alignfree" and self.boolean(c, attribute, value):
                    # MuJoCo then moves a free body's frame to its inertial frame, so its qpos is that
                    # frame's pose; kinedyn keeps the body frame the file writes
                    self.ignored.add(
                        "<compiler alignfree='true'> (kinedyn's q of a free body is its body frame's pose, not MuJoCo's aligned qpos)"
                    )

    @staticmethod
    def boolean_value(value: str) -> bool | None:
        return {"true": True, "false": False}.get(value)

    def boolean(self, element, attribute: str, value: str) -> bool:
        b = self.boolean_value(value)
        if b is None:
            raise self.src.error(element, f"attribute '{attribute}' must be true or false, got '{short(value)}'")
        return b

    def option(self) -> tuple:
        """``<option>`` (MuJoCo's XML reference, "option"): gravity and the flags that change the
        passive joint forces kinedyn models are read; the fluid model is named as not modelled
        (see the module docstring for every attribute)."""
        gravity = (0.0, 0.0, -9.81)
        self.damping_on, self.frictionloss_on = True, True
        for o in self.root.iter("option"):
            if o.get("gravity") is not None:
                gravity = numbers(o, "gravity", self.src, 3)
            fluid = [k for k in FLUID_OPTIONS if k in o.attrib and any(numbers(o, k, self.src))]
            if fluid:
                given = ", ".join(f"{k}='{short(o.get(k))}'" for k in fluid)
                self.ignored.add(f"fluid forces (<option {given}>: MuJoCo's drag, lift and wind on every body)")
            for flag in o.iterfind("flag"):
                if flag.get("gravity") == "disable":
                    gravity = (0.0, 0.0, 0.0)
                # MuJoCo's disable flags: 'damper' (older: 'passive') drops joint damping;
                # 'frictionloss' (or every constraint, 'constraint') drops dry friction
                if "disable" in (flag.get("damper"), flag.get("passive")):
                    self.damping_on = False
                if "disable" in (flag.get("frictionloss"), flag.get("constraint")):
                    self.frictionloss_on = False
            for child in o:
                if child.tag == "plugin":
                    self.ignored.add(f"<option><plugin> '{child.get('plugin', '')}' (its forces)")
        return gravity

    def read_defaults(self, element, name: str, inherited: dict, top: bool = False) -> None:
        """One ``<default>`` class and those nested in it. Every top-level ``<default>`` is MuJoCo's
        ``main`` class: a second one (the Jaco arm's, from an included file) adds to it, as MuJoCo's
        reader does; a nested class defined twice is refused (MuJoCo: "repeated default class name")."""
        cls = element.get("class") or name
        if top and cls == "main" and "main" in self.defaults:
            own = self.defaults["main"]  # the classes already read keep the copy they inherited
        elif cls in self.defaults:
            raise self.src.error(element, f"class '{cls}' is defined twice")
        else:
            own = {t: dict(a) for t, a in inherited.items()}
        for child in element:
            if child.tag in DEFAULTED:
                own[child.tag].update(child.attrib)
        self.defaults[cls] = own
        for child in element:
            if child.tag == "default":
                if not child.get("class"):
                    raise self.src.error(child, "a nested <default> needs a 'class' attribute")
                self.read_defaults(child, child.get("class"), own)

    def attributes(self, element, childclass: str) -> dict:
        """The element's attributes over its default class's."""
        cls = element.get("class") or childclass
        if cls not in self.defaults:
            if cls == "main":
                return dict(element.attrib)
            raise self.src.error(element, f"class='{cls}' names no <default> class")
        out = dict(self.defaults[cls].get(element.tag, {}))
        if element.tag == "geom" and "size" in out and "size" in element.attrib:
            # MuJoCo reads the numbers given over the default's (a sphere's size="r" keeps the rest)
            given = element.get("size").split()
            rest = out["size"].split()[len(given) :]
            out["size"] = " ".join(given + rest)
            element = {k: v for k, v in element.attrib.items() if k != "size"}
            out.update(element)
            return out
        out.update(element.attrib)
        return out
