"""The outcome of a property check: one :class:`Check` per property (with how it was decided, its
residual and tolerance) and the :class:`PropertiesReport` that holds them, for a robot
(:func:`~kinedyn.analysis.properties.check_properties`), symbolic equations
(:func:`~kinedyn.analysis.proofs.prove_properties`) or a Lagrangian system
(:func:`~kinedyn.analysis.system_properties.check_system_properties`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..display import properties_html

__all__ = ["STATUSES", "Check", "PropertiesReport"]


#: how a check was decided: exact simplification, numbers at random states, a global optimisation, a
#: simulated trajectory; "failed" (a counterexample) and "skipped" (could not be evaluated, says why)
STATUSES = ("proved", "sampled", "searched", "simulated", "failed", "skipped")


@dataclass
class Check:
    """One property: ``passed`` when ``residual <= tolerance``; ``detail`` says what was measured;
    ``status`` how it was decided (one of :data:`STATUSES`; "sampled" or "failed" when not given)."""

    name: str
    passed: bool
    residual: float
    tolerance: float
    detail: str = ""
    source: str = ""
    data: dict = field(default_factory=dict)
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = "sampled" if self.passed else "failed"
        elif not self.passed:
            self.status = "failed"
        if self.status not in STATUSES:
            raise ValueError(f"check status must be one of {STATUSES}, got {self.status!r}")

    @property
    def proved(self) -> bool:
        return self.status == "proved"

    def to_dict(self) -> dict:
        return dict(
            name=self.name,
            passed=self.passed,
            status=self.status,
            residual=self.residual,
            tolerance=self.tolerance,
            detail=self.detail,
            source=self.source,
            **{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.data.items()},
        )


@dataclass
class PropertiesReport:
    robot: str
    samples: int
    checks: list

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def __getitem__(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name or c.name.startswith(name):
                return c
        raise KeyError(f"no check named '{name}' (checks: {[c.name for c in self.checks]})")

    def to_dict(self) -> dict:
        return dict(
            robot=self.robot, samples=self.samples, passed=self.passed, checks=[c.to_dict() for c in self.checks]
        )

    def _repr_html_(self) -> str:  # notebooks: the checks as a table (kinedyn.display)
        return properties_html(self)

    def __str__(self) -> str:
        lines = [f"properties of '{self.robot}' over {self.samples} sampled states:"]
        for c in self.checks:
            mark = "FAIL" if not c.passed else c.status
            lines.append(f"  [{mark:9s}] {c.name}: residual {c.residual:.3g} (tolerance {c.tolerance:.3g}); {c.detail}")
        return "\n".join(lines)
