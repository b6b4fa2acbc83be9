"""Expressions in robot files and on the command line, read as data: never ``eval``, never ``sympify``.

A robot file may write a value as ``"m1*l1**2/12"`` or ``"pi/2"``. ``sympy.sympify`` would hand such a
string to Python's ``eval`` (a string of letters, digits, ``(``, ``)`` and ``+`` can reach ``exec``), and
even SymPy's own arithmetic can be asked for unbounded work (``9**9**9``, ``factorial(10**7)``). This
module parses the text with :func:`ast.parse` (which only builds a syntax tree) and walks the tree,
admitting only

- numeric literals (integers and decimals, no complex numbers),
- names, which become ``sympy.Symbol`` s (or the caller's own symbols), and the constant ``pi``,
- ``+ - * / **``, unary ``-`` and ``+``, parentheses,
- calls of the fixed function table :data:`FUNCTIONS` with positional arguments,

and building the SymPy objects directly. The work is bounded: the text's length, the tree's depth
and size, every exponent, and the size of every number computed on the way. Any other input is a
``ValueError`` that says what is wrong.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Mapping
from typing import TYPE_CHECKING, Union

from ._lazy import LazyModule, sympy_instance

if TYPE_CHECKING:
    import sympy as sp
else:
    sp = LazyModule("sympy")  # SymPy loads on first use, not with kinedyn (kinedyn._lazy)


__all__ = [  # noqa: F822 - FUNCTIONS and CONSTANTS come from the module __getattr__
    "FUNCTIONS",
    "CONSTANTS",
    "parse_expression",
    "parse_number",
    "MAX_LENGTH",
    "MAX_DEPTH",
    "MAX_EXPONENT",
]

# the functions a file may call: name -> (SymPy function's name, number of arguments); FUNCTIONS and
# CONSTANTS, with the SymPy objects themselves, are made on first use (module __getattr__ below)
_FUNCTION_NAMES: dict = {
    "sin": ("sin", 1),
    "cos": ("cos", 1),
    "tan": ("tan", 1),
    "asin": ("asin", 1),
    "acos": ("acos", 1),
    "atan": ("atan", 1),
    "atan2": ("atan2", 2),
    "sinh": ("sinh", 1),
    "cosh": ("cosh", 1),
    "tanh": ("tanh", 1),
    "sqrt": ("sqrt", 1),
    "exp": ("exp", 1),
    "log": ("log", 1),
    "abs": ("Abs", 1),
}
_CONSTANT_NAMES = ("pi",)


def __getattr__(name: str):
    """FUNCTIONS (name -> (SymPy function, arity)) and CONSTANTS (name -> SymPy constant), built when
    first read: building them imports SymPy (kinedyn._lazy)."""
    if name == "FUNCTIONS":
        return {k: (getattr(sp, f), arity) for k, (f, arity) in _FUNCTION_NAMES.items()}
    if name == "CONSTANTS":
        return {k: getattr(sp, k) for k in _CONSTANT_NAMES}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


MAX_LENGTH = 1000  # characters of one expression
MAX_DEPTH = 32  # nesting of the syntax tree (parentheses, operators, calls)
MAX_NODES = 400  # nodes of the syntax tree
MAX_EXPONENT = 64  # |p| in x**p, and p must be a number
MAX_NAME = 64  # characters of one symbol name
MAX_BITS = 1100  # numerator/denominator bits of any exact number met on the way (|x| < ~1e330)
MAX_FLOAT = 1e300  # |x| of any number met on the way

_BINARY = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_UNARY = {ast.USub: "-", ast.UAdd: "+"}


class _Refused(ValueError):
    """Internal: carries the reason up to parse_expression, which adds the text."""


def parse_expression(
    text: str,
    symbols: Mapping[str, sp.Basic] | None = None,
    *,
    allow_symbols: bool = True,
) -> Union[float, sp.Expr]:
    """``text`` as a float when it names a number, else as a SymPy expression.

    ``symbols`` maps names to the caller's own SymPy objects (a system's coordinates, say); any other
    name becomes ``sympy.Symbol(name)`` when ``allow_symbols`` is true and is an error otherwise.
    Raises ``ValueError`` naming the problem for anything that is not arithmetic on numbers and names,
    for unbounded work, and for results that are not finite real numbers.
    """
    if not isinstance(text, str):
        raise ValueError(f"expected an expression as text, got {type(text).__name__}")
    shown = text if len(text) <= 60 else text[:57] + "..."
    try:
        expr = _parse(text, symbols or {}, allow_symbols)
    except _Refused as e:
        raise ValueError(f"'{shown}' is not a number or an arithmetic expression of names: {e}") from None
    return expr


_PLAIN_NUMBER = re.compile(r"[+-]?((0|[1-9]\d*)(\.\d*)?|\.\d+)([eE][+-]?\d+)?")  # as Python writes a literal


def parse_number(text: str) -> float:
    """A finite real number written as text (``"2.5"``, ``"pi/2"``, ``"sqrt(2)/2"``): no names allowed."""
    if isinstance(text, str) and len(text) <= MAX_LENGTH and _PLAIN_NUMBER.fullmatch(text.strip()):
        value = float(text)  # a plain decimal (most command lines): no SymPy needed
        if abs(value) <= MAX_FLOAT:
            return value
    value = parse_expression(text, allow_symbols=False)
    return float(value)


# ------------------------------------------------------------------ the walk
def _parse(text: str, symbols: Mapping[str, sp.Basic], allow_symbols: bool):
    if len(text) > MAX_LENGTH:
        raise _Refused(f"longer than {MAX_LENGTH} characters")
    if not text.strip():
        raise _Refused("it is empty")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, MemoryError, RecursionError) as e:  # ValueError: a NUL byte
        reason = getattr(e, "msg", None) or type(e).__name__
        raise _Refused(f"invalid syntax ({reason})") from None
    nodes = sum(1 for _ in ast.walk(tree))
    if nodes > MAX_NODES:
        raise _Refused(f"more than {MAX_NODES} terms")
    walker = _Walker(symbols, allow_symbols)
    expr = walker.visit(tree.body, 0)
    return _finish(expr)


class _Walker:
    def __init__(self, symbols: Mapping[str, sp.Basic], allow_symbols: bool):
        self.symbols = symbols
        self.allow_symbols = allow_symbols

    def visit(self, node: ast.AST, depth: int) -> sp.Basic:
        if depth > MAX_DEPTH:
            raise _Refused(f"nested more than {MAX_DEPTH} deep")
        if isinstance(node, ast.Constant):
            return _literal(node.value)
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
            operand = self.visit(node.operand, depth + 1)
            return _bounded(-operand if isinstance(node.op, ast.USub) else operand)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            left = self.visit(node.left, depth + 1)
            right = self.visit(node.right, depth + 1)
            return _bounded(_binary(node.op, left, right))
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        raise _Refused(
            f"{_describe(node)} is not allowed (only numbers, names, + - * / **, parentheses and {', '.join(_FUNCTION_NAMES)})"
        )

    def name(self, name: str) -> sp.Basic:
        if name in self.symbols:
            return self.symbols[name]
        if name in _CONSTANT_NAMES:
            return getattr(sp, name)
        if name.lower() in ("nan", "inf", "infinity"):
            raise _Refused(f"'{name}' is not a finite number (and not allowed as a name)")
        if name in _FUNCTION_NAMES:
            raise _Refused(f"'{name}' is a function: call it, e.g. {name}(x)")
        if not self.allow_symbols:
            raise _Refused(f"'{name}' is a name, but a number is needed here")
        if len(name) > MAX_NAME or name.startswith("_") or not name.isascii():
            raise _Refused(
                f"'{name[:MAX_NAME]}' is not a valid name (ASCII letters, digits and _, not starting with _, at most {MAX_NAME} characters)"
            )
        return sp.Symbol(name)

    def call(self, node: ast.Call, depth: int) -> sp.Basic:
        if not isinstance(node.func, ast.Name) or node.func.id not in _FUNCTION_NAMES:
            called = node.func.id if isinstance(node.func, ast.Name) else _describe(node.func)
            raise _Refused(f"'{called}' is not a known function (known: {', '.join(_FUNCTION_NAMES)})")
        name, arity = _FUNCTION_NAMES[node.func.id]
        function = getattr(sp, name)
        if node.keywords or len(node.args) != arity or any(isinstance(a, ast.Starred) for a in node.args):
            raise _Refused(f"{node.func.id} takes {arity} positional argument{'s' if arity > 1 else ''}")
        args = [self.visit(a, depth + 1) for a in node.args]
        return _bounded(function(*args))


def _literal(value) -> sp.Basic:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _Refused(f"{type(value).__name__} literal {value!r:.40} is not allowed (only real numbers)")
    if isinstance(value, int):
        if value.bit_length() > MAX_BITS:
            raise _Refused(f"the integer literal has more than {MAX_BITS} bits")
        return sp.Integer(value)
    if not math.isfinite(value):
        raise _Refused("a number literal overflows to infinity")
    return sp.Float(value)


def _binary(op: ast.operator, a: sp.Basic, b: sp.Basic) -> sp.Basic:
    if isinstance(op, ast.Add):
        return a + b
    if isinstance(op, ast.Sub):
        return a - b
    if isinstance(op, ast.Mult):
        return a * b
    if isinstance(op, ast.Div):
        if b == 0:
            raise _Refused("division by zero")
        return a / b
    # ast.Pow: the exponent is a number of bounded size, so that no step can ask for unbounded work
    if not (sympy_instance(b, "Number") and abs(float(b)) <= MAX_EXPONENT):
        raise _Refused(f"an exponent must be a number between -{MAX_EXPONENT} and {MAX_EXPONENT}, got {_short(b)}")
    if a == 0 and b < 0:
        raise _Refused("division by zero (0 to a negative power)")
    return a**b


def _bounded(e: sp.Basic) -> sp.Basic:
    """Refuse a value met on the way that is not a finite real number or is too large to be a robot's
    parameter; checking every step bounds the work of the next one (``exp(exp(exp(10)))`` stops at
    the second ``exp``)."""
    if sympy_instance(e, "Rational"):
        if e.p.bit_length() > MAX_BITS or e.q.bit_length() > MAX_BITS:
            raise _Refused(f"a number on the way is too large (more than {MAX_BITS} bits)")
        return e
    if e.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise _Refused("the result is not a finite number")
    if not e.free_symbols:
        _numeric_value(e)
    return e


def _numeric_value(e: sp.Basic) -> float:
    """The value of a constant expression, or _Refused when it is not a finite real of bounded size."""
    try:
        value = complex(sp.N(e, 17))
    except (TypeError, ValueError, OverflowError, ZeroDivisionError) as err:
        raise _Refused(f"it cannot be evaluated ({type(err).__name__})") from None
    if value.imag != 0:
        raise _Refused("a value on the way is not a real number")
    if not math.isfinite(value.real) or abs(value.real) > MAX_FLOAT:
        raise _Refused(f"a number on the way is not finite or larger than {MAX_FLOAT:g}")
    return value.real + 0.0


def _finish(e: sp.Basic) -> Union[float, sp.Expr]:
    if not sympy_instance(e, "Expr"):
        raise _Refused(f"the result is a {type(e).__name__}, not an expression")
    if e.has(sp.I):
        raise _Refused("the result is not a real number")
    return e if e.free_symbols else _numeric_value(e)


def _describe(node: ast.AST) -> str:
    kinds = {
        ast.Attribute: "attribute access (a.b)",
        ast.Subscript: "indexing (a[b])",
        ast.Lambda: "lambda",
        ast.Compare: "a comparison",
        ast.BoolOp: "and/or",
        ast.IfExp: "if/else",
        ast.List: "a list",
        ast.Tuple: "a tuple",
        ast.Dict: "a dict",
        ast.Set: "a set",
        ast.JoinedStr: "an f-string",
    }
    for kind, words in kinds.items():
        if isinstance(node, kind):
            return words
    if isinstance(node, ast.BinOp):
        return f"the operator {type(node.op).__name__}"
    if isinstance(node, ast.UnaryOp):
        return f"the unary operator {type(node.op).__name__}"
    return type(node).__name__


def _short(e) -> str:
    text = str(e) if sympy_instance(e, "Symbol") or (sympy_instance(e, "Rational") and e.p.bit_length() < 100) else ""
    return text[:40] if text and len(text) <= 40 else f"a {type(e).__name__}"
