"""Fixtures of the OpenSees export tests: the OpenSeesPy module and script loading."""

import importlib.util
import sys

import pytest

from tests.conftest import unavailable


@pytest.fixture(scope="module")
def ops():
    """openseespy.opensees, loaded by the toolkit's one loader (fails in CI if missing)."""
    from multimass.errors import InputError
    from multimass.export import import_opensees

    try:
        return import_opensees()
    except InputError as exc:
        unavailable(str(exc))


def load_script(path):
    """Import an exported script as a module (its ``__main__`` block does not run)."""
    name = f"exported_{path.stem}_{abs(hash(str(path)))}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def fresh(ops, module):
    """Build the script's model in an empty 2-D domain; returns the module."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    module.build(ops)
    module.analysis(ops)
    return module
