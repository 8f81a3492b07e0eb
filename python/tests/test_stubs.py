"""The type stubs (`_core.pyi`) say what the compiled module takes: every
function and method of the stub has the module's parameters, in order, and
the module has nothing callable the stub does not declare."""

import ast
import inspect
from pathlib import Path

import friction_node._core as core

STUB = Path(__file__).resolve().parents[1] / "friction_node" / "_core.pyi"


def stub_signatures():
    """{qualified name: [parameter names]} of the stub's functions and methods."""
    tree = ast.parse(STUB.read_text())
    out = {}

    def params(f):
        a = f.args
        return [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs if p.arg != "self"]

    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            out[node.name] = params(node)
        elif isinstance(node, ast.ClassDef):
            for m in node.body:
                if isinstance(m, ast.FunctionDef) and not any(
                    isinstance(d, ast.Name) and d.id == "property" for d in m.decorator_list
                ):
                    out[f"{node.name}.{m.name}"] = params(m)
    return out


def module_parameters(qualified):
    obj = core
    for part in qualified.split("."):
        obj = getattr(obj, part)
    if qualified.endswith(".__init__"):
        obj = getattr(core, qualified.split(".")[0])
    return [p for p in inspect.signature(obj).parameters if p != "self"]


def test_every_stub_signature_matches_the_compiled_module():
    stubs = stub_signatures()
    assert "fit" in stubs and "rotary" in stubs["fit"]
    for name, params in stubs.items():
        assert module_parameters(name) == params, name


def test_the_stub_declares_every_function_of_the_module():
    stubs = stub_signatures()
    public = [n for n in dir(core) if not n.startswith("_") and inspect.isbuiltin(getattr(core, n))]
    assert public, dir(core)
    missing = [n for n in public if n not in stubs]
    assert not missing, missing
