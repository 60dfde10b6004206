"""How a rocking structure vibrates: linearisation, Foss state-space modes, MAC, reports.

>>> from multimass import modal
>>> res = modal.analyse("S1")
>>> [round(f, 1) for f in res.rocking.freq_hz[:2]]
[20.5, 45.6]
"""

if __name__ != "multimass.modal":  # one import name (a linked folder)
    raise ImportError(
        f"this folder installs as `multimass.modal`; import that, not "
        f"`{__name__}` (is the repository's root on sys.path before site-packages?)"
    )

from .analysis import ModalAnalysis, PhaseModes, analyse, default_shape_nodes
from .assurance import mac
from .eigen import (
    StateSpaceModes,
    foss,
    frequency_and_damping,
    pair_frequency_and_damping,
    state_matrix,
)
from .errors import ModalError
from .frequency_response import frf, sensor_nodes, state_space
from .linearisation import LinearSystem, full_contact, linearise, rocking
from .measured_frf import MeasuredFRF, full_contact_h1, full_contact_segments, h1_estimate

__all__ = [
    "LinearSystem",
    "MeasuredFRF",
    "ModalAnalysis",
    "ModalError",
    "PhaseModes",
    "StateSpaceModes",
    "analyse",
    "default_shape_nodes",
    "foss",
    "frf",
    "frequency_and_damping",
    "full_contact",
    "full_contact_h1",
    "full_contact_segments",
    "h1_estimate",
    "linearise",
    "mac",
    "pair_frequency_and_damping",
    "rocking",
    "sensor_nodes",
    "state_matrix",
    "state_space",
]
