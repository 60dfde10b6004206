"""Excitations as (kind, params, samples) for the compiled kernels.

The compiled path evaluates ü_g(t) inside machine code, so it must know the
formula: `encode` maps the excitation classes of `multimass.inputs.excitations` and
`multimass.inputs.records` (exact classes, not subclasses, whose formula could
differ) to a kind code of `multimass.engines.fast._maths.ground_acc`, a float array
of parameters and an array of samples (a record's accelerations). Anything
else — a user's own callable — is refused with an `InputError` that names it
and points to ``backend="scipy"``.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...inputs.excitations import CosinePulse, CosineWave, FreeRelease, MPPulse, Ricker, SineWave
from ...inputs.records import Record
from . import _maths as mx

__all__ = ["encode", "KNOWN"]

#: The excitation classes the compiled kernels evaluate.
KNOWN = (FreeRelease, SineWave, CosineWave, CosinePulse, Ricker, MPPulse, Record)

_NO_SAMPLES = np.zeros(2)


def _params(*values) -> np.ndarray:
    out = np.zeros(mx.PAR_SIZE)
    out[: len(values)] = values
    return out


def encode(excitation) -> tuple[int, np.ndarray, np.ndarray]:
    """(kind, params, samples) of a known excitation.

    Parameters
    ----------
    excitation : FreeRelease, SineWave, CosineWave, CosinePulse, Ricker, MPPulse or Record

    Returns
    -------
    kind : int
        An ``EXC_*`` code of `multimass.engines.fast._maths`.
    params : ndarray, shape (PAR_SIZE,)
    samples : ndarray
        The record's accelerations (m/s²), else two zeros.

    Raises
    ------
    InputError
        For any other excitation (the compiled kernels cannot call Python).
    """
    tp = type(excitation)
    if tp is FreeRelease:
        return mx.EXC_NONE, _params(), _NO_SAMPLES
    if tp is SineWave:
        return (
            mx.EXC_SINE,
            _params(excitation.amplitude, excitation.omega, excitation.duration),
            _NO_SAMPLES,
        )
    if tp is CosineWave:
        return (
            mx.EXC_COSINE,
            _params(excitation.amplitude, excitation.omega, excitation.duration),
            _NO_SAMPLES,
        )
    if tp is CosinePulse:
        return (
            mx.EXC_COSINE,
            _params(excitation.amplitude, excitation.omega, excitation.duration),
            _NO_SAMPLES,
        )
    if tp is Ricker:
        return (
            mx.EXC_RICKER,
            _params(excitation.amplitude, excitation.omega, excitation.t0, excitation.duration),
            _NO_SAMPLES,
        )
    if tp is MPPulse:
        e = excitation
        par = _params(e.amplitude, e.fp, e.gamma, e.nu, e.t0, e.start, e.duration)
        return mx.EXC_MP, par, _NO_SAMPLES
    if tp is Record:
        time = excitation.time
        # the interpolation constants of Record.acceleration: t_start, t_end, 1/dt, last interval
        par = _params(float(time[0]), float(time[-1]), 1.0 / excitation.dt, time.size - 2)
        return mx.EXC_RECORD, par, np.array(excitation.accel, dtype=np.float64)
    name = getattr(excitation, "kind", None) or tp.__name__
    raise InputError(
        f"`excitation` = {name!r} ({tp.__module__}.{tp.__qualname__}): "
        "backend='compiled' evaluates only "
        f"{', '.join(k.__name__ for k in KNOWN)} inside its kernels; "
        "use backend='scipy' for this excitation"
    )
