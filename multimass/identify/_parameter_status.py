"""Which model parameters an identification was given, estimated or took from the file.

Every result of `multimass.identify.restitution` and `multimass.identify.calibrate`
says, for each parameter of the model it fitted, where its value came from:

* ``given`` — by the user (a keyword, a CLI flag): used as it is;
* ``estimated`` — from the traces, with its standard deviation (marginal: from the
  covariance of every unknown fitted together) and 95 % interval (± 1.96 std; for the
  parameters fitted as logarithms, C_p and ζ, exp(log value ± 1.96 std of the log));
* ``ill-posed`` — fitted, but the traces do not fix it: its std is beyond
  `LIMITS` (restitution 0.02, C_p and ζ 25 %), it is not finite, or it is correlated
  beyond `LIMITS["correlation"]` (0.98) with another unknown, which is named; its
  value is then not an estimate: `explored` replaces its std and 95 % interval by the
  range the fit was allowed to explore (``interval_kind`` "explored range", the value
  "best fit, not an estimate"), all that the data say of it;
* ``fixed by the specimen file`` — the column's geometry, masses and stiffnesses
  (and, where the user fixed the fit list, the parameters left out of it); also a
  parameter the identification was to estimate and could not at all (`not_estimated`:
  no impact fitted), whose ``not_estimated`` says why — the result is then ill-posed
  (`overall`), not estimated;
* ``not used`` — a parameter the chosen model does not have (C_p of CIM).
"""

from __future__ import annotations

import math

__all__ = [
    "GIVEN", "ESTIMATED", "ILL_POSED", "FIXED", "NOT_USED", "STRUCTURE_FIELDS", "Z95",
    "INTERVAL_95", "EXPLORED", "given", "estimated", "estimated_note", "explored", "fixed",
    "not_estimated",
    "not_used", "structure_fixed", "ill_posed_reasons",
    "lines", "overall",
]  # fmt: skip

GIVEN = "given"
ESTIMATED = "estimated"
ILL_POSED = "ill-posed"
FIXED = "fixed by the specimen file"
NOT_USED = "not used"
#: ``interval_kind`` of an estimated parameter's interval and of an ill-posed one's.
INTERVAL_95 = "95 %"
EXPLORED = "explored range"
#: The two-sided 95 % quantile of the normal distribution.
Z95 = 1.959963984540054
#: The specimen's fields that every identification takes as they are (its geometry,
#: masses, stiffnesses, gravity and sensor positions).
STRUCTURE_FIELDS = ("heights", "masses", "m0", "J0", "B", "E_s", "I_s", "K_rot", "K_fp", "g",
                    "sensors")  # fmt: skip


_LOG_STD_MAX = 50.0  # a log's std beyond which exp() of the interval overflows


def given(value: float, what: str = "") -> dict:
    """A parameter the user gave."""
    return {"status": GIVEN, "value": float(value), "std": None, "interval": None, "what": what}


def fixed(value, what: str = "", note: str = "") -> dict:
    """A parameter taken from the specimen file."""
    out = {"status": FIXED, "value": value, "std": None, "interval": None, "what": what}
    return out | ({"note": note} if note else {})


def not_estimated(value, what: str, why: str) -> dict:
    """A parameter the identification was to estimate but could not (`why`): the specimen
    file's `value` stands in, and `overall` makes the result ill-posed for it."""
    return fixed(value, what, why) | {"not_estimated": why}


def not_used(why: str, what: str = "") -> dict:
    """A parameter the model does not have."""
    return {"status": NOT_USED, "value": None, "std": None, "interval": None, "what": what,
            "note": why}  # fmt: skip


def estimated_note(what: str) -> dict:
    """Quantities estimated from the traces whose values are elsewhere in the result."""
    return {"status": ESTIMATED, "value": None, "std": None, "interval": None, "what": what}


def estimated(value: float, std: float, log: bool = False, what: str = "") -> dict:
    """A parameter estimated from the traces: `std` is that of the value, or of its
    logarithm if `log`; the interval is the 95 % one."""
    s = float(std)
    if not math.isfinite(s) or (log and s > _LOG_STD_MAX):  # no interval to speak of
        interval, s_value = None, (value * s if math.isfinite(s) else math.inf)
    elif log:
        interval = [value * math.exp(-Z95 * s), value * math.exp(Z95 * s)]
        s_value = value * s
    else:
        interval = [value - Z95 * s, value + Z95 * s]
        s_value = s
    out = {"status": ESTIMATED, "value": float(value), "std": s_value, "interval": interval,
           "what": what}  # fmt: skip
    return out | ({"interval_kind": INTERVAL_95} if interval is not None else {})


def explored(entry: dict, low: float, high: float) -> dict:
    """An ill-posed parameter's `entry` as what the data allow: no std, its interval the
    range [`low`, `high`] the fit was allowed to explore (``interval_kind`` "explored
    range"), its value kept as the best fit, not an estimate."""
    return entry | {"std": None, "interval": [float(low), float(high)],
                    "interval_kind": EXPLORED, "value_kind": "best fit, not an estimate"}  # fmt: skip


def structure_fixed(spec) -> dict:
    """The specimen's fields every identification takes from the file, with their values."""
    out = {}
    for name in STRUCTURE_FIELDS:
        value = getattr(spec, name, None)
        if value is None:
            continue
        if isinstance(value, tuple):
            value = [list(v) if isinstance(v, tuple) else v for v in value]
        out[name] = value
    return out


def ill_posed_reasons(std: float, limit, correlated: dict, log: bool = False) -> list[str]:
    """Why a fitted parameter is not fixed by the traces (empty: it is): its std (of the
    log for `log` parameters) beyond `limit` (None: no limit), not finite, or its
    correlations beyond `LIMITS["correlation"]` (`correlated`: the other unknown's name →
    correlation)."""
    out = []
    if not math.isfinite(std):
        out.append("the traces do not constrain it (singular Jacobian)")
    elif limit is not None and std > limit:
        what = "relative std" if log else "std"
        out.append(f"{what} {std:.3g} above {limit:g}")
    for other, c in correlated.items():
        out.append(f"cannot be separated from {other} (correlation {c:+.3f})")
    return out


def overall(parameters: dict) -> tuple[str, str]:
    """(status, message): ``ill-posed`` naming the parameters the traces do not fix and
    why (ill-posed ones, and those that could not be estimated at all: `not_estimated`),
    else ``estimated``."""
    why = [f"{n}: {p.get('reason', '')}" for n, p in parameters.items()
           if p.get("status") == ILL_POSED]  # fmt: skip
    why += [f"{n}: {p['not_estimated']} (the specimen file's value stands in)"
            for n, p in parameters.items() if p.get("not_estimated")]  # fmt: skip
    if why:
        return ILL_POSED, f"not fixed by the trace(s): {'; '.join(why)}"
    return ESTIMATED, "every parameter not given was estimated from the trace(s)"


def _fmt(p: dict) -> str:
    v, s = p.get("value"), p.get("std")
    if isinstance(v, float) and p.get("interval_kind") == EXPLORED:
        lo, hi = p["interval"]
        return (
            f"not fixed by the traces: anywhere in {lo:.5g} … {hi:.5g} "
            f"(best fit {v:.5g}, not an estimate)"
        )
    if isinstance(v, float):
        text = f"{v:.5g}"
        if s is not None:
            text += f" ± {s:.2g}" if math.isfinite(s) else " ± ∞"
        if p.get("interval"):
            lo, hi = p["interval"]
            text += f" (95 %: {lo:.5g} … {hi:.5g})"
        return text
    return "" if v is None else str(v)


def lines(parameters: dict, width: int = 10) -> list[str]:
    """One text line per parameter: ``name  status  value ± std (95 %: lo … hi)``, with the
    reason of an ill-posed one and the note of a fixed or unused one."""
    out = []
    for name, p in parameters.items():
        extra = p.get("reason") or p.get("note") or ""
        text = f"{name:<{width}} {p['status']}: {_fmt(p)}".rstrip(": ")
        out.append(text + (f" — {extra}" if extra else ""))
    return out
