"""Reading a scene from a TOML file or a parsed mapping (schema in `multimass.scenes.scene`)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import multimass.specimens as specimens

from ..errors import InputError
from ..inputs.excitations import CosinePulse, CosineWave, FreeRelease, MPPulse, Ricker, SineWave
from ..inputs.records import read_record
from ..inputs.textfile import as_path, read_text
from ..inputs.units import G, parse_acceleration
from .question import _ABS_KEYS, Question, Tolerance, _fail, _keys, _number

__all__ = ["scene_arguments", "arguments_from_mapping", "resolve_path"]

_WHAT = "a scene TOML file (see examples/scenes/)"


def scene_arguments(path) -> dict:
    """Read and validate a scene file: the keyword arguments of its `Scene`; relative paths
    inside it resolve against its folder.

    Raises
    ------
    InputError
        If `path` is not a readable UTF-8 TOML file (missing, a directory, empty,
        binary, not UTF-8, bad syntax) or the scene inside is invalid.
    """
    p = as_path(path, what=_WHAT, argument="scene")
    text = read_text(p, what=_WHAT, argument="scene", suffixes=(".toml",))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not valid TOML ({exc}); fix the syntax") from None
    return arguments_from_mapping(data, str(p), p.parent)


_EXC_KEYS = {
    "free_release": ({"theta0_rad", "theta0_deg", "u0_m"}, set()),
    "sine_wave": (set(), {"amplitude", "omega_rad_per_s"}),
    "cosine_wave": (set(), {"amplitude", "omega_rad_per_s"}),
    "cosine_pulse": (set(), {"amplitude", "omega_rad_per_s"}),
    "ricker": ({"t0_s"}, {"amplitude", "omega_rad_per_s"}),
    "mp_pulse": ({"gamma", "nu_rad", "t0_s"}, {"amplitude_m_per_s", "fp_hz"}),
    "record": ({"units", "scale"}, {"path"}),
}


def resolve_path(value: str, folder: Path, bundled=()) -> str:
    """A bundled name as is; otherwise a path, relative ones taken from `folder`."""
    if value in bundled:
        return value
    p = Path(value).expanduser()
    return str(p if p.is_absolute() else (folder / p))


def _structure(data, w: str, folder: Path) -> dict:
    _keys(w, "structure", data, {"beam", "E_Pa", "E_over_Ebar"}, {"specimen"})
    for key in ("specimen", "beam"):
        if key in data and (not isinstance(data[key], str) or not data[key]):
            raise _fail(w, f"structure.{key}", data[key], "give a bundled name or a TOML path")
    names = set(specimens.available())
    out = {"specimen": resolve_path(data["specimen"], folder, names)}
    if "beam" in data:
        out["beam"] = resolve_path(data["beam"], folder, names)
    if "E_Pa" in data and "E_over_Ebar" in data:
        raise InputError(f"{w}: give one of `structure.E_Pa` and `structure.E_over_Ebar`, not both")
    if "E_Pa" in data:
        out["E"] = _number(
            w, "structure.E_Pa", data["E_Pa"], low=0.0, low_open=True, what="Young's modulus in Pa"
        )
    elif "E_over_Ebar" in data:
        ratio = _number(
            w,
            "structure.E_over_Ebar",
            data["E_over_Ebar"],
            low=0.0,
            low_open=True,
            what="E / Ē, Ē giving a midspan deflection L/2500 (paper 002, Section 6.3)",
        )
        if "beam" not in out:
            raise InputError(f"{w}: `structure.E_over_Ebar` needs `structure.beam`")
        out["E_over_Ebar"] = ratio
    return out


def _amplitude(w: str, data) -> float:
    return abs(parse_acceleration(data["amplitude"], None, argument=f"{w}: excitation.amplitude"))


def _excitation(data, w: str, folder: Path):
    if not isinstance(data, dict) or "kind" not in data:
        raise InputError(f"{w}: missing key `excitation.kind`; use one of {', '.join(_EXC_KEYS)}")
    kind = data["kind"]
    if kind not in _EXC_KEYS:
        raise _fail(w, "excitation.kind", kind, f"use one of {', '.join(_EXC_KEYS)}")
    optional, required = _EXC_KEYS[kind]
    _keys(w, "excitation", data, optional | {"kind"}, required)
    if kind == "free_release":
        if ("theta0_rad" in data) == ("theta0_deg" in data):
            raise InputError(
                f"{w}: a free release needs exactly one of `excitation.theta0_rad` "
                "and `excitation.theta0_deg`"
            )
        th = (
            _number(w, "excitation.theta0_rad", data["theta0_rad"], what="an angle in rad")
            if "theta0_rad" in data
            else math.radians(
                _number(w, "excitation.theta0_deg", data["theta0_deg"], what="an angle in deg")
            )
        )
        u0 = data.get("u0_m")
        if u0 is not None:
            u0 = _number(w, "excitation.u0_m", u0, what="the top node's initial displacement in m")
        return FreeRelease(theta0=th, u0=u0)
    if kind == "record":
        if not isinstance(data["path"], str):
            raise _fail(w, "excitation.path", data["path"], "give the record file's path")
        scale = _number(
            w,
            "excitation.scale",
            data.get("scale", 1.0),
            low=0.0,
            low_open=True,
            what="a factor on the record",
        )
        path = Path(resolve_path(data["path"], folder))
        if not path.is_file():
            raise _fail(
                w,
                "excitation.path",
                data["path"],
                f"no such file ({path}); paths are relative to the scene file's folder",
            )
        return read_record(path, units=data.get("units"), scale=scale)
    if kind == "mp_pulse":
        return _mp_pulse(data, w)
    omega = _number(
        w,
        "excitation.omega_rad_per_s",
        data["omega_rad_per_s"],
        low=0.0,
        low_open=True,
        what="a circular frequency in rad/s",
    )
    amp = _amplitude(w, data)
    if kind == "sine_wave":
        return SineWave(amplitude=amp, omega=omega)
    if kind == "cosine_wave":
        return CosineWave(amplitude=amp, omega=omega)
    if kind == "cosine_pulse":
        return CosinePulse(omega=omega, amplitude=amp)
    t0 = data.get("t0_s")
    if t0 is not None:
        t0 = _number(w, "excitation.t0_s", t0, low=0.0, low_open=True, what="the centre in s")
    return Ricker(amplitude=amp, omega=omega, t0=t0)


def _mp_pulse(data, w: str) -> MPPulse:
    """An M&P pulse (`multimass.MPPulse`) from its TOML keys; MPPulse checks its ranges."""
    num = lambda key, what: _number(w, f"excitation.{key}", data[key], what=what)
    kw = {
        "amplitude": num("amplitude_m_per_s", "the velocity amplitude A in m/s"),
        "fp": num("fp_hz", "the pulse frequency f_p in Hz"),
    }
    for key, name, what in (
        ("gamma", "gamma", "γ > 1"),
        ("nu_rad", "nu", "the phase ν in rad"),
        ("t0_s", "t0", "the envelope's peak time in s"),
    ):
        if key in data:
            kw[name] = num(key, what)
    try:
        return MPPulse(**kw)
    except InputError as exc:
        raise InputError(f"{w}: [excitation] {exc}") from None


def _question(data, w: str) -> Question:
    if not isinstance(data, dict):
        raise _fail(w, "question", data, "expected a table; write it as [question]")
    _keys(w, "question", data, {"node", "sensor", "n_modes", "after_impacts"}, {"kind"})
    kw = {k: data[k] for k in ("node", "sensor", "n_modes", "after_impacts") if k in data}
    try:
        return Question(data["kind"], **kw)
    except InputError as exc:
        raise InputError(f"{w}: {str(exc).removeprefix('question: ')}") from None


def _tolerance(data, w: str, question: Question) -> Tolerance | None:
    if data is None:
        if question.kind == "overturning":
            return None
        raise InputError(
            f"{w}: missing table [tolerance]; add e.g. `relative = 0.05` (5 %) or "
            f"an absolute tolerance in the answer's unit ({question.unit})"
        )
    _keys(w, "tolerance", data, {"relative", *_ABS_KEYS})
    if len(data) != 1:
        raise InputError(
            f"{w}: [tolerance] needs exactly one of `relative`, "
            f"{', '.join('`' + k + '`' for k in _ABS_KEYS)}; got {sorted(data) or 'none'}"
        )
    ((key, value),) = data.items()
    if key == "relative":
        return Tolerance(
            _number(
                w,
                "tolerance.relative",
                value,
                low=0.0,
                low_open=True,
                high=1.0,
                what="a fraction, e.g. 0.05 for 5 %",
            ),
            relative=True,
        )
    unit, factor = _ABS_KEYS[key]
    x = _number(w, f"tolerance.{key}", value, low=0.0, low_open=True, what=f"a tolerance in {unit}")
    if factor is None:  # absolute_g: in units of g
        factor = G
    return Tolerance(x * factor, relative=False, unit=unit)


def _simulation(data, w: str) -> dict:
    if data is None:
        return {}
    _keys(
        w,
        "simulation",
        data,
        {"t_end_s", "impact", "restitution", "max_step_s", "nscd_dt_s", "nscd_elements"},
    )
    names = {
        "t_end_s": "t_end",
        "impact": "impact",
        "restitution": "restitution",
        "max_step_s": "max_step",
        "nscd_dt_s": "nscd_dt",
        "nscd_elements": "nscd_elements",
    }
    return {names[k]: v for k, v in data.items()}


def arguments_from_mapping(data, source: str, folder: Path) -> dict:
    """The keyword arguments of a `Scene`, from a parsed TOML mapping (`Scene.from_toml`
    builds the scene); `source` names the file in errors."""
    w = source
    _keys(
        w,
        "",
        data,
        {"description", "tolerance", "simulation"},
        {"name", "structure", "excitation", "question"},
    )
    if not isinstance(data["name"], str) or not data["name"].strip():
        raise _fail(w, "name", data["name"], "give the scene a name")
    st = _structure(data["structure"], w, Path(folder))
    exc = _excitation(data["excitation"], w, Path(folder))
    question = _question(data["question"], w)
    tol = _tolerance(data.get("tolerance"), w, question)
    ratio = st.pop("E_over_Ebar", None)
    if ratio is not None:
        import multimass.engines.nscd as nscd

        try:
            st["E"] = nscd.flexible_modulus(st["specimen"], st["beam"]) * ratio
        except ValueError as exc_:
            raise InputError(f"{w}: `structure` = {data['structure']!r}: {exc_}") from None
    return dict(
        name=data["name"],
        description=str(data.get("description", "")),
        excitation=exc,
        question=question,
        tolerance=tol,
        source=source,
        **st,
        **_simulation(data.get("simulation"), w),
    )
