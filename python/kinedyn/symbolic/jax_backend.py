"""``eom.compile(backend="jax")``: the equations of motion as JAX functions, for learning through the
dynamics.

The functions have the interface of the other compiled backends (:class:`kinedyn.symbolic.codegen.CompiledEOM`):
``fn.M(q)``, ``fn.C(q, qd)``, ``fn.g(q)``, ``fn.tau(q, qd, qdd)`` (and ``fn.friction(qd)`` when asked),
each taking one state (n,) or a batch (N, n) (a batch is mapped with ``jax.vmap``). They are
``jax.jit``-ed, and compose with ``jax.jit``, ``jax.vmap``, ``jax.grad``, ``jax.jacfwd``/``jacrev``.

The SymPy programs of :mod:`kinedyn.symbolic.codegen` (common subexpressions eliminated; for large
models the CSE form of :mod:`kinedyn.symbolic.cse`) are traced, node by node, into ``jax.numpy``
operations by :class:`kinedyn.symbolic.translate.Walker`.

Precision: the functions compute in float64. JAX defaults to float32, so requesting this backend
turns on ``jax.config.update("jax_enable_x64", True)`` (a process-wide JAX setting). Importing kinedyn
never does; only ``compile(backend="jax")`` does. Derivatives of ``sign`` (Coulomb friction) are zero,
as in kinedyn's analytical derivatives (qd != 0).
"""

from __future__ import annotations

from typing import Any, Dict

import numpy as np
import sympy as sp

__all__ = ["compile_jax"]


def _jax():
    try:
        import jax
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("backend='jax' needs JAX: pip install 'kinedyn[scale]' (or pip install jax)") from exc
    jax.config.update("jax_enable_x64", True)  # float64: see the module docstring
    return jax


def _functions(jnp) -> Dict[str, Any]:
    return {"sin": jnp.sin, "cos": jnp.cos, "tan": jnp.tan, "exp": jnp.exp, "log": jnp.log, "sqrt": jnp.sqrt,
            "fabs": jnp.abs, "sign": jnp.sign, "asin": jnp.arcsin, "acos": jnp.arccos, "atan": jnp.arctan,
            "atan2": jnp.arctan2, "sinh": jnp.sinh, "cosh": jnp.cosh, "tanh": jnp.tanh, "fmax": jnp.maximum,
            "fmin": jnp.minimum}


def compile_jax(eom, what=("M", "C", "g", "tau"), params=None, p=None):
    """JAX functions of ``eom`` (see the module docstring); ``params`` and ``p`` as in ``eom.compile``."""
    from .codegen import _ARGS, CompiledEOM, _blocks, _params_by_name, generate
    from .translate import Walker

    jax = _jax()
    import jax.numpy as jnp

    params = _params_by_name(eom, params)
    blocks, pars = _blocks(eom, what, params)
    if pars and p is None:
        raise ValueError(f"the equations still contain the parameters {[str(s) for s in pars]}: give their values, compile(params={{...}})")
    if p is not None and len(p) != len(pars):
        raise ValueError(f"p has {len(p)} values, the equations have {len(pars)} parameters {[str(s) for s in pars]}")
    pvals = jnp.asarray(np.asarray([] if p is None else p, dtype=float), dtype=jnp.float64)
    n = eom.n
    fns = _functions(jnp)
    funcs = {}
    for name, shape, assignments, exprs in blocks:
        args = _ARGS[name]

        def single(*xs, _name=name, _shape=shape, _assign=assignments, _exprs=exprs, _args=args):
            env: Dict[sp.Symbol, Any] = {}
            for a, x in zip(_args, xs):
                for i in range(n):
                    env[sp.Symbol(f"{a}[{i}]")] = x[i]
            for i in range(len(pars)):
                env[sp.Symbol(f"p[{i}]")] = pvals[i]
            walker = Walker(env, fns, constant=lambda c: jnp.asarray(c, dtype=jnp.float64))
            walker.assign(_assign)
            values = [jnp.asarray(walker(e), dtype=jnp.float64) for e in _exprs]
            return jnp.stack(values).reshape(_shape)

        def call(*xs, _single=single, _name=name, _args=args):
            if len(xs) != len(_args):
                raise TypeError(f"{_name} takes {len(_args)} arrays ({', '.join(_args)}), got {len(xs)}")
            xs = tuple(jnp.asarray(x, dtype=jnp.float64) for x in xs)
            first = xs[0]
            if first.ndim not in (1, 2) or first.shape[-1] != n:
                raise ValueError(f"{_name}: expected arrays of shape ({n},) or (N, {n}), got {first.shape}")
            for a, v in zip(_args, xs):
                if v.shape != first.shape:
                    raise ValueError(f"{_name}: {a} has shape {v.shape}, expected {first.shape}")
            return _single(*xs) if first.ndim == 1 else jax.vmap(_single)(*xs)

        jitted = jax.jit(call)
        jitted.__doc__ = f"{name}({', '.join(args)}) of {eom.name or 'the system'} in JAX (one state (n,) or a batch (N, n))."
        funcs[name] = jitted
    src = generate(eom, "numpy", what, name="kd", params=params)  # the same program, readable
    out = CompiledEOM("jax", funcs, n, src, [] if p is None else list(p))
    return out
