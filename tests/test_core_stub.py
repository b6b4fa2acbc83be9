"""The native module's stub (python/kinedyn/_core.pyi: what IDEs complete and the API reference
shows) describes the compiled module: the same public classes and functions, each class's methods,
static methods and properties, and for every callable the same parameters in the same order with
defaults in the same places. (An introspection equivalent of ``mypy.stubtest`` for this module, in
about a second: PyO3 gives each binding a ``__text_signature__``.) Names starting with ``_`` are
private and left out; module-level assignments in the stub are stub-only type aliases."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

core = pytest.importorskip("kinedyn._core", reason="the native module is not built")

STUB = Path(__file__).resolve().parents[1] / "python" / "kinedyn" / "_core.pyi"


def _params(fn: ast.FunctionDef, drop_first: bool) -> list:
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
    out = [(p.arg, d) for p, d in zip(positional, defaults)]
    out += [(p.arg, d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    return out[1:] if drop_first else out


def _decorators(fn: ast.FunctionDef) -> set:
    return {d.id if isinstance(d, ast.Name) else getattr(d, "attr", "") for d in fn.decorator_list}


def stub_api() -> dict:
    api = {}
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            api[node.name] = ("function", _params(node, False))
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            members, init = {}, None
            for item in node.body:
                if not isinstance(item, ast.FunctionDef):
                    continue
                decorators = _decorators(item)
                if item.name in ("__init__", "__new__"):
                    init = _params(item, True)
                elif item.name.startswith("_"):
                    continue
                elif "property" in decorators:
                    members[item.name] = ("property", None)
                elif "staticmethod" in decorators:
                    members[item.name] = ("staticmethod", _params(item, False))
                else:
                    members[item.name] = ("method", _params(item, True))
            api[node.name] = ("class", init, members)
    return api


def _signature(obj, drop_first: bool):
    sig = inspect.signature(obj)
    out = [(p.name, p.default is not inspect.Parameter.empty) for p in sig.parameters.values()]
    return out[1:] if drop_first else out


def runtime_api() -> dict:
    api = {}
    for name, obj in vars(core).items():
        if name.startswith("_") or inspect.ismodule(obj):
            continue
        if inspect.isclass(obj):
            members = {}
            for m, v in vars(obj).items():
                if m.startswith("_"):
                    continue
                if inspect.isgetsetdescriptor(v) or isinstance(v, property):
                    members[m] = ("property", None)
                elif isinstance(v, staticmethod) or inspect.isbuiltin(v):  # PyO3 #[staticmethod]
                    members[m] = ("staticmethod", _signature(getattr(obj, m), False))
                else:
                    members[m] = ("method", _signature(v, True))
            init = None
            if obj.__text_signature__ is not None:  # PyO3 #[new]: "(a, b, ...)"
                init = _signature(obj, False)
            api[name] = ("class", init, members)
        elif callable(obj):
            api[name] = ("function", _signature(obj, False))
    return api


def test_stub_has_the_compiled_modules_names():
    stub, runtime = stub_api(), runtime_api()
    assert sorted(set(runtime) - set(stub)) == [], "compiled but missing from _core.pyi"
    assert sorted(set(stub) - set(runtime)) == [], "in _core.pyi but not in the compiled module"


@pytest.mark.parametrize("name", sorted(runtime_api()))
def test_stub_signatures_match(name):
    stub, runtime = stub_api()[name], runtime_api()[name]
    assert stub[0] == runtime[0], f"{name}: {stub[0]} in the stub, {runtime[0]} compiled"
    if runtime[0] == "function":
        assert stub[1] == runtime[1], f"{name}: parameters (name, has default) differ"
        return
    _, stub_init, stub_members = stub
    _, run_init, run_members = runtime
    if issubclass(getattr(core, name), BaseException):
        return  # an exception class: no constructor of its own to describe
    assert stub_init == run_init, f"{name}(): constructor parameters differ"
    assert sorted(stub_members) == sorted(run_members), f"{name}: members differ"
    for m in run_members:
        assert stub_members[m] == run_members[m], f"{name}.{m}: kind or parameters (name, has default) differ"
