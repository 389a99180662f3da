"""Every public function and class documents itself (STYLE.md practice 10).

Tier (c) behaviour: walks each module's ``__all__`` and checks for a docstring, and for
functions with parameters, that a numpydoc "Parameters" section or a one-line summary that
names them exists; rejects unknown keyword arguments on the main entry points.
"""

import importlib
import inspect
import pkgutil

import pytest

import cmsim


def public_objects():
    for info in pkgutil.walk_packages(cmsim.__path__, "cmsim."):
        if info.name.split(".")[-1].startswith("_"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                if obj.__module__ == module.__name__:
                    yield f"{info.name}.{name}", obj


OBJECTS = sorted(public_objects())


@pytest.mark.parametrize("name, obj", OBJECTS, ids=[n for n, _ in OBJECTS])
def test_public_object_has_docstring(name, obj):
    doc = inspect.getdoc(obj)
    assert doc and len(doc.strip()) > 10, f"{name} has no docstring"


def test_there_is_a_public_api():
    assert len(OBJECTS) > 40


@pytest.mark.parametrize("func, kwargs", [
    ("cmsim.dynamics.simulate", dict(duration_s=0.01, fs=75000)),
    ("cmsim.dynamics.modal.modal_analysis", dict(positions=8)),
])
def test_unknown_keywords_are_rejected(func, kwargs):
    module, name = func.rsplit(".", 1)
    f = getattr(importlib.import_module(module), name)
    with pytest.raises(TypeError, match="unexpected keyword"):
        f(cmsim.Rig.paper_2016(), cmsim.OperatingPoint(1000, 10), **kwargs)
