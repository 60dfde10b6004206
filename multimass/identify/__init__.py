"""From test traces back to the model: synthetic traces with a known truth.

* `synthetic_trace` — a realistic trace simulated by the toolkit: per-impact
  restitution drawn and stored, an anti-alias filter and 200 Hz sampling, sensor
  noise, sensor bias and a clock offset; its truth goes to a sidecar file
  (`SyntheticTrace.write`, `read_truth`), never into the trace;
* `multimass.identify.sampling` — the anti-alias filter and the sampling it uses;
* `segment_trace` — a trace cut into rocking half-cycles, impacts and full contact;
* `restitution` — each impact's coefficient of restitution, by the paper's energy
  estimate and by fitting the impact model (paper 001, Section 4.3), with the corner
  means and a ``[restitution]`` specimen fragment;
* `operational_modes` — vibration frequencies, damping and operational shapes of the
  rocking half-cycles and full-contact stretches, against `multimass.modal.analyse`
  (paper 001, Section 4.2, Fig 5);
* `calibrate` — restitution means, C_p and damping fitted to one or more traces by
  least squares, with uncertainties and an honest status (paper 001, Sections 2.4, 4.3).
"""

from .calibration import FITTABLE, Calibration, calibrate
from .impacts import RestitutionEstimate, energy_restitution, restitution
from .impacts_plots import plot_restitution
from .modes import IdentifiedModes, OperationalModes, operational_modes
from .sampling import anti_alias_fir, fir_figures, resample
from .segments import HalfCycle, ImpactMark, Segments, segment_trace
from .synthetic import SyntheticTrace, read_truth, synthetic_trace, truth_path

__all__ = [
    "SyntheticTrace",
    "synthetic_trace",
    "read_truth",
    "truth_path",
    "anti_alias_fir",
    "fir_figures",
    "resample",
    "segment_trace",
    "Segments",
    "HalfCycle",
    "ImpactMark",
    "restitution",
    "RestitutionEstimate",
    "energy_restitution",
    "plot_restitution",
    "operational_modes",
    "OperationalModes",
    "IdentifiedModes",
    "calibrate",
    "Calibration",
    "FITTABLE",
]
