"""The package's layout: module paths written before the subpackages still import, each
module loads once, and the root holds only the entry points and the shared contract."""

import importlib
import subprocess
import sys

import pytest

from multimass import _paths
from tests.conftest import REPO


@pytest.mark.parametrize("old", sorted(_paths.MOVED))
def test_an_old_module_path_is_the_module_at_its_new_path(old):
    new = _paths.MOVED[old]
    assert importlib.import_module(old) is importlib.import_module(new)
    assert sys.modules[old].__spec__.name == new  # its own spec, not the alias's


def test_a_module_inside_a_moved_package_loads_once():
    # run in a fresh interpreter: the old path first, as a user's script would
    code = (
        "import sys, multimass.fast.compile as a, multimass.engines.fast.compile as b;"
        "print(a is b, len({id(m) for m in sys.modules.values()"
        " if getattr(m, '__file__', None) == a.__file__}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "1"]


def test_the_public_names_of_old_paths_import():
    from multimass.fragility import fit_lognormal
    from multimass.records import read_record
    from multimass.structure import column

    assert fit_lognormal.__module__ == "multimass.analysis.fragility"
    assert read_record.__module__ == "multimass.inputs.records"
    assert column.__module__ == "multimass.model.structure"


def test_an_unknown_module_is_still_an_import_error():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("multimass.no_such_module")
    assert _paths.new_path("multimass.no_such_module") is None
    assert _paths.new_path("numpy.linalg") is None


def test_the_root_holds_at_most_twelve_modules():
    modules = sorted(p.name for p in (REPO / "multimass").glob("*.py") if p.name != "__init__.py")
    assert len(modules) <= 12, modules
