"""Bridges to other engines: a specimen's model written for OpenSees (`opensees`).

Lives here: the exporter (`opensees`), its script sections, and the one OpenSeesPy loader
(`import_opensees`). May import the model, specimens, records and modal; nothing imports it but the CLI.
"""

from ._runtime import import_opensees
from .opensees import PHASES, default_dt, opensees

__all__ = ["opensees", "PHASES", "default_dt", "import_opensees"]
