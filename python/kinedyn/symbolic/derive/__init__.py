"""Derivation, below :class:`~kinedyn.symbolic.EquationsOfMotion` (which it never imports): the
Euler-Lagrange model in an exact trigonometric ring (:mod:`.lagrange`), the customised Newton-Euler
model (:mod:`.newton_euler`), its common-subexpression form (:mod:`.cse`), trigonometric normal forms
(:mod:`.simplify`), symbolic kinematics (:mod:`.kinematics`), the regressor (:mod:`.regressor`) and the
proofs of Spong §9.5 (:mod:`.proofs`). :mod:`kinedyn.symbolic.systems` builds the equations object from
these."""
