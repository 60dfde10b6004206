"""The one OpenSeesPy loader: its message when OpenSeesPy is missing, and its one source."""

import importlib.util

import pytest

from multimass.errors import InputError
from multimass.export import _runtime, import_opensees, opensees


def test_missing_openseespy_names_the_extra(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "openseespy" else real(name)
    )
    with pytest.raises(InputError, match=r'pip install "multimass\[opensees\]"'):
        import_opensees()


def test_unloadable_openseespy_says_why(monkeypatch):
    def broken():
        raise ImportError("libblas.so.3: cannot open shared object file")

    monkeypatch.setattr(_runtime, "load_opensees", broken)
    with pytest.raises(InputError, match="libblas.so.3.*reinstall"):
        import_opensees()


def test_scripts_carry_the_loader_verbatim():
    """The exported script's loader is the library's, copied from its source: one loader."""
    source = _runtime.loader_source()
    assert source.startswith("def load_opensees():")
    for phase, kw in (("full-contact", {}), ("rocking", {"release": 0.1})):
        assert source in opensees("S1" if phase != "rocking" else "B6M", phase, **kw)
