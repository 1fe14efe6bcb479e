"""The .pyi stubs describe the module exactly: every public name and every
public member of every class, no more, no less."""
import ast
import importlib
import os

import pytest

import gssm

STUBS = os.path.join(os.path.dirname(gssm.__file__))
MODULES = ["gssm", "gssm.models", "gssm.io", "gssm.analysis", "gssm.campaign"]


def stub_tree(module):
    name = "__init__" if module == "gssm" else module.split(".")[1]
    return ast.parse(open(os.path.join(STUBS, name + ".pyi")).read())


def stub_classes(tree):
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}

    def members(cls):
        out = set()
        for b in cls.bases:
            if isinstance(b, ast.Name) and b.id in classes:
                out |= members(classes[b.id])
        for n in cls.body:
            if isinstance(n, ast.FunctionDef) and (not n.name.startswith("_") or n.name == "__len__"):
                out.add(n.name)
            elif isinstance(n, ast.AnnAssign):
                out.add(n.target.id)
        return out

    return {name: members(c) for name, c in classes.items()}


@pytest.mark.parametrize("module", MODULES)
def test_stub_names_match_the_module(module):
    mod = importlib.import_module(module)
    tree = stub_tree(module)
    declared = {n.name for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    public = set(mod.__all__) - {"models", "io", "analysis"}
    assert declared == public, (sorted(declared - public), sorted(public - declared))
    for name, members in stub_classes(tree).items():
        cls = getattr(mod, name)
        real = {m for m in dir(cls) if not m.startswith("_")} | ({"__len__"} if hasattr(cls, "__len__") else set())
        real -= {"with_traceback", "args", "add_note"}  # BaseException's own
        assert members == real, (name, sorted(members - real), sorted(real - members))
