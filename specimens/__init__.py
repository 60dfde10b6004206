"""What is simulated: validated, immutable specimen descriptions in SI units.

Specimens are TOML files; the bundled ones live in ``specimens/data``. Every value is
validated on loading — its type, its sign and its physical plausibility
(`specimens.ranges`: a modulus typed in GPa or a height in mm is refused with the fix).

>>> from multimass import specimens
>>> s1 = specimens.load("S1")
>>> s1.heights[-1]
1.93
"""

if __name__ != "multimass.specimens":  # one import name (a linked folder)
    raise ImportError(
        f"this folder installs as `multimass.specimens`; import that, not "
        f"`{__name__}` (is the repository's root on sys.path before site-packages?)"
    )

from .beam import BeamSpecimen
from .block import BlockReference, BlockSpecimen
from .column import ColumnReference, ColumnSpecimen
from .errors import SpecimenError
from .loader import available, from_mapping, load, register_kind

__all__ = [
    "BeamSpecimen",
    "BlockReference",
    "BlockSpecimen",
    "ColumnReference",
    "ColumnSpecimen",
    "SpecimenError",
    "available",
    "from_mapping",
    "load",
    "register_kind",
]
