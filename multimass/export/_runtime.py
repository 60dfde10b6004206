"""Importing OpenSeesPy: the one loader, used here and emitted into every exported script.

The Linux wheel of OpenSeesPy (package ``openseespylinux``) bundles its own BLAS,
LAPACK and Fortran run-time in ``openseespylinux/lib``, but its extension module
finds ``liblapack.so.3`` by its run path while LAPACK's own dependency
``libblas.so.3`` is looked up on the system's library path, where a machine without
a system BLAS has none: ``import openseespy.opensees`` then fails with "Failed to
import openseespy on Linux". Loading the bundled libraries first, globally
(``ctypes.RTLD_GLOBAL``), lets the dynamic linker resolve them from memory.

`load_opensees` depends on the standard library only, so its source is copied
verbatim into the exported scripts (`loader_source`): there is one loader.
"""

from __future__ import annotations

import inspect

from ..errors import InputError

__all__ = ["load_opensees", "import_opensees", "loader_source", "INSTALL_HINT"]

#: How a user gets OpenSeesPy with the toolkit.
INSTALL_HINT = 'pip install "multimass[opensees]"'


def load_opensees():
    """Import and return ``openseespy.opensees``, loading the wheel's bundled BLAS first.

    Returns None if OpenSeesPy is not installed; raises ImportError if it is
    installed but cannot be loaded.
    """
    import ctypes
    import importlib
    import importlib.util
    import os
    import sys

    if importlib.util.find_spec("openseespy") is None:
        return None
    if sys.platform.startswith("linux"):
        spec = importlib.util.find_spec("openseespylinux")
        for folder in spec.submodule_search_locations if spec else ():
            lib = os.path.join(folder, "lib")
            # dependencies first: Fortran run-time, then BLAS, then LAPACK (needs BLAS)
            for name in ("libquadmath.so.0", "libgfortran.so.4", "libblas.so.3", "liblapack.so.3"):
                path = os.path.join(lib, name)
                if os.path.exists(path):
                    ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    try:
        return importlib.import_module("openseespy.opensees")
    except RuntimeError as exc:  # the package wraps every load failure in a RuntimeError
        raise ImportError(f"OpenSeesPy is installed but does not load: {exc}") from exc


def import_opensees():
    """The ``openseespy.opensees`` module, ready to use.

    Raises
    ------
    InputError
        If OpenSeesPy is not installed (the message says how to install it) or
        cannot be loaded on this machine (the message carries the reason).
    """
    try:
        module = load_opensees()
    except (ImportError, OSError) as exc:
        raise InputError(
            f"OpenSeesPy cannot be loaded ({exc}); reinstall it with `{INSTALL_HINT}`"
        ) from None
    if module is None:
        raise InputError(
            f"OpenSeesPy is not installed; running OpenSees models needs `{INSTALL_HINT}`"
        )
    return module


def loader_source() -> str:
    """The source text of `load_opensees`, as it is written into exported scripts."""
    return inspect.getsource(load_opensees)
