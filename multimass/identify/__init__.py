"""From test traces back to the model (issue 14): synthetic traces with a known truth.

* `synthetic_trace` — a realistic trace simulated by the toolkit: per-impact
  restitution drawn and stored, an anti-alias filter and 200 Hz sampling, sensor
  noise, sensor bias and a clock offset; its truth goes to a sidecar file
  (`SyntheticTrace.write`, `read_truth`), never into the trace;
* `multimass.identify.sampling` — the anti-alias filter and the sampling it uses.
"""

from .sampling import anti_alias_fir, fir_figures, resample
from .synthetic import SyntheticTrace, read_truth, synthetic_trace, truth_path

__all__ = [
    "SyntheticTrace",
    "synthetic_trace",
    "read_truth",
    "truth_path",
    "anti_alias_fir",
    "fir_figures",
    "resample",
]
