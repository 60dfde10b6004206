"""Operational modes on synthetic S1–S3 free-vibration traces.

0.11 rad release, DD2 and CIM, 200 Hz, noise 2 % of each channel's peak, seeds 1–3,
10 s (and 20 s, where the rocking of S2 lasts so long that 10 s leave too little full
contact). For every case: the identified uplifted f1, f2 and full-contact f1 against
`multimass.modal.analyse` (the reference: the model that made the trace), the worst MAC
against the model's compound (rocking) and full-contact shapes, the modes reported as
not identifiable, and the wall time.

    python -m benchmarks.identify_modes [--specimens S1,S2,S3] [--seeds 1,2,3]
"""

from __future__ import annotations

import argparse
import time

from multimass import FreeRelease, modal
from multimass.errors import InputError
from multimass.identify import operational_modes, synthetic_trace

__all__ = ["main", "one"]


def _error(pm, ref, mode: int) -> str:
    """Identified vs model frequency of `mode`, in %, or why it is missing."""
    if pm is None:
        return "absent"
    if mode not in list(pm.mode):
        return "n/i"
    k = list(pm.mode).index(mode)
    return f"{100 * (pm.freq_hz[k] / ref.freq_hz[mode - 1] - 1):+.2f} %"


def one(spec: str, impact: str, seed: int, t_end: float) -> dict:
    """Identify one synthetic trace; a row of text fields."""
    syn = synthetic_trace(spec, FreeRelease(theta0=0.11), impact, t_end, seed=seed)
    model = modal.analyse(spec)
    wall = time.perf_counter()
    try:
        om = operational_modes(syn.trace, spec)
    except InputError as err:  # e.g. no full contact in a short S2 trace: say so
        return {"case": f"{spec} {impact} seed {seed} {t_end:g} s", "error": str(err)[:90]}
    wall = time.perf_counter() - wall
    rk, fc = om.rocking, om.full_contact
    macs = [m for pm in (rk, fc) if pm is not None for m in pm.mac]
    return {
        "case": f"{spec} {impact} seed {seed} {t_end:g} s",
        "uplifted f1": _error(rk, model.rocking, 1),
        "uplifted f2": _error(rk, model.rocking, 2),
        "full-contact f1": _error(fc, model.full_contact, 1),
        "min MAC": f"{min(macs):.4f}" if macs else "-",
        "not identified": ", ".join(
            f"{ph[0]}{j}" for ph, pm in (("r", rk), ("f", fc)) if pm for j in pm.not_identified
        ),
        "s": f"{wall:.1f}",
    }


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--specimens", default="S1,S2,S3")
    ap.add_argument("--impacts", default="DD2,CIM")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--durations", default="10,20")
    args = ap.parse_args(argv)
    rows = []
    for spec in args.specimens.split(","):
        for impact in args.impacts.split(","):
            for seed in (int(s) for s in args.seeds.split(",")):
                for t_end in (float(d) for d in args.durations.split(",")):
                    rows.append(one(spec, impact, seed, t_end))
                    print(" | ".join(f"{k}: {v}" for k, v in rows[-1].items()), flush=True)
    return rows


if __name__ == "__main__":
    main()
