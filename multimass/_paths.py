"""The module paths users already write, kept working after the modules found their rooms.

`multimass.fragility`, `multimass.records`, `multimass.newmark`, `multimass.fast`, … now
live in subpackages by concept (`multimass.analysis.fragility`, `multimass.inputs.records`,
`multimass.engines.newmark`, `multimass.engines.fast`, …). `install` puts a finder on
`sys.meta_path` that answers an import of an old path with the module at its new one — the
same module object, under both names — so ``from multimass.fragility import fit_lognormal``
and ``import multimass.fast.compile`` keep working. Private modules (a leading underscore)
have no old path.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

__all__ = ["MOVED", "new_path", "install"]

#: Old public module path → its path now.
MOVED = {
    f"multimass.{name}": f"multimass.{room}.{name}"
    for room, names in {
        "model": (
            "structure", "structure_checks", "kinematics", "eom", "equations", "damping",
            "beam", "symbolic", "flexible_oscillator_eom",
        ),
        "inputs": ("excitations", "pulse_shapes", "records", "units", "textfile", "samples",
                   "traces"),
        "engines": ("contact_dynamics", "newmark", "poisson_block", "flexible_oscillator",
                    "fast", "nscd"),
        "analysis": ("intensity", "fragility", "trace_metrics", "plots"),
    }.items()
    for name in names
}  # fmt: skip


def new_path(fullname: str) -> str | None:
    """The path now of module `fullname` (or of a module inside a moved package), or None."""
    head, _, rest = fullname.partition(".")
    if head != "multimass" or not rest:
        return None
    parts = fullname.split(".")
    old = ".".join(parts[:2])
    if old not in MOVED:
        return None
    return MOVED[old] + fullname[len(old) :]


class _OldPaths(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old path and loads it as the module at its new path."""

    def find_spec(self, fullname, path=None, target=None):
        new = new_path(fullname)
        if new is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        module = importlib.import_module(new_path(spec.name))
        self._own = getattr(module, "__spec__", None)
        return module

    def exec_module(self, module):
        # the import system set the old path's spec on the module: give it its own back
        module.__spec__ = self._own


def install() -> None:
    """Put the finder of old paths on `sys.meta_path` (once)."""
    # first: the path finder would otherwise load a module inside a moved package (say
    # ``multimass.fast.compile``) a second time, from the folder it found it in
    if not any(isinstance(f, _OldPaths) for f in sys.meta_path):
        sys.meta_path.insert(0, _OldPaths())
