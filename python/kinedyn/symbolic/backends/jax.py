"""``eom.compile(backend="jax")``: the equations of motion as JAX functions, for learning through the
dynamics.

The functions have the interface of the other compiled backends (:class:`kinedyn.symbolic.backends.program.CompiledEOM`):
``fn.M(q)``, ``fn.C(q, qd)``, ``fn.g(q)``, ``fn.tau(q, qd, qdd)`` (and ``fn.friction(qd)`` when asked),
each taking one state (n,) or a batch (N, n) (a batch is mapped with ``jax.vmap``). Parameters left
symbolic are given at compile time (``p=``) and may be replaced at call time by the keyword ``p=``, a
JAX input like any other (``jax.grad`` with respect to the parameters, for identification or learning). They are
``jax.jit``-ed, and compose with ``jax.jit``, ``jax.vmap``, ``jax.grad``, ``jax.jacfwd``/``jacrev``.

The SymPy programs of :mod:`kinedyn.symbolic.codegen` (common subexpressions eliminated; for large
models the CSE form of :mod:`kinedyn.symbolic.cse`) are printed once as straight-line ``jax.numpy``
code (SymPy's ``JaxPrinter``; ``fn.source``), so tracing under ``jit``/``grad`` replays plain Python
assignments, not a walk over SymPy trees.

Precision: the functions compute in float64. JAX defaults to float32, so requesting this backend
turns on ``jax.config.update("jax_enable_x64", True)`` (a process-wide JAX setting). Importing kinedyn
never does; only ``compile(backend="jax")`` does. Derivatives of ``sign`` (Coulomb friction) are zero,
as in kinedyn's analytical derivatives (qd != 0).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import program
from .program import ARGS, CompiledEOM

__all__ = ["compile_jax"]


def _jax():
    try:
        import jax
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("backend='jax' needs JAX: pip install 'kinedyn[scale]' (or pip install jax)") from exc
    jax.config.update("jax_enable_x64", True)  # float64: see the module docstring
    return jax


def compile_jax(eom, what=("M", "C", "g", "tau"), params=None, p=None):
    """JAX functions of ``eom`` (see the module docstring); ``params`` and ``p`` as in ``eom.compile``."""
    from sympy.printing.numpy import JaxPrinter  # with the JAX back-end only, as jax itself

    jax = _jax()
    import jax.numpy as jnp

    params = program.params_by_name(eom, params)
    blocks, pars = program.blocks(eom, what, params)
    if pars and p is None:
        raise ValueError(
            f"the equations still contain the parameters {[str(s) for s in pars]}: give their values, compile(params={{...}})"
        )
    if p is not None and len(p) != len(pars):
        raise ValueError(f"p has {len(p)} values, the equations have {len(pars)} parameters {[str(s) for s in pars]}")
    pvals = jnp.asarray(np.asarray([] if p is None else p, dtype=float), dtype=jnp.float64)
    n = eom.n
    printer = JaxPrinter({"fully_qualified_modules": True})
    lines = ["def _f(x):", "    return jnp.asarray(x, dtype=jnp.float64)", ""]
    for name, shape, assignments, exprs in blocks:
        lines.append(f"def single_{name}({', '.join(ARGS[name])}, p):")
        lines += [f"    {s} = {printer.doprint(e)}" for s, e in assignments]
        lines.append(
            "    return jnp.stack(["
            + ", ".join(f"_f({printer.doprint(e)})" for e in exprs)
            + f"]).reshape({tuple(shape)!r})"
        )
        lines.append("")
    source = "\n".join(lines).replace("jax.numpy.", "jnp.").replace("numpy.", "jnp.")
    namespace: dict[str, Any] = {"jnp": jnp, "jax": jax}
    exec(compile(source, "<kinedyn jax>", "exec"), namespace)
    funcs = {}
    for name, _shape, _, _ in blocks:
        funcs[name] = _callable(jax, jnp, name, namespace[f"single_{name}"], n, pvals)
    return CompiledEOM("jax", funcs, n, source, [] if p is None else list(p))


def _callable(jax, jnp, name: str, single, n: int, pvals):
    """The jitted function ``name`` of one state (n,) or a batch (N, n) (mapped with ``jax.vmap``)."""
    args = ARGS[name]

    def call(*xs, p=None):
        if len(xs) != len(args):
            raise TypeError(f"{name} takes {len(args)} arrays ({', '.join(args)}), got {len(xs)}")
        xs = tuple(jnp.asarray(x, dtype=jnp.float64) for x in xs)
        first = xs[0]
        if first.ndim not in (1, 2) or first.shape[-1] != n:
            raise ValueError(f"{name}: expected arrays of shape ({n},) or (N, {n}), got {first.shape}")
        for a, v in zip(args, xs):
            if v.shape != first.shape:
                raise ValueError(f"{name}: {a} has shape {v.shape}, expected {first.shape}")
        pv = pvals if p is None else jnp.asarray(p, dtype=jnp.float64)
        if pv.shape != pvals.shape:
            raise ValueError(
                f"{name}: p has shape {pv.shape}, expected {pvals.shape} (the parameters in eom.parameters order)"
            )
        if first.ndim == 1:
            return single(*xs, pv)
        return jax.vmap(lambda *x: single(*x, pv))(*xs)

    call.__name__ = name
    call.__doc__ = (
        f"{name}({', '.join(args)}, p=None) in JAX: one state (n,) or a batch (N, n); float64; "
        "p: parameter values replacing those given at compile time (differentiable)."
    )
    return jax.jit(call)
