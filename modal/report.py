"""Modal reports: a JSON-ready summary and a Markdown page against published values.

Plotting lives in `modal.plots` and `modal.frf_plots`; this module only computes and formats.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from multimass.model.structure import column

from .analysis import ModalAnalysis, analyse, nodal_points
from .errors import ModalError
from .measured import MeasuredShapes
from .measured_frf import MeasuredFRF

__all__ = ["summary", "markdown", "write_report", "printed_unit", "MIXED_PARTICIPATION"]

_E_SENSITIVITY = 210e9  # Pa; DESIGN.md: brings S1's full-contact pair within 0.2 %


def printed_unit(value: float) -> float:
    """One unit of the last printed digit of a published value (298 → 1, 0.84 → 0.01).

    Read from the shortest decimal representation, so a trailing zero the
    paper printed (e.g. "2.50") is not seen and the unit is looser (0.1).
    """
    s = repr(float(value))
    if "e" in s or "E" in s:
        mantissa, exp = s.lower().split("e")
        decimals = len(mantissa.split(".")[1].rstrip("0")) if "." in mantissa else 0
        return 10.0 ** (int(exp) - decimals)
    frac = s.split(".")[1].rstrip("0") if "." in s else ""
    return 10.0 ** (-len(frac))


def _floats(a) -> list[float]:
    return [float(x) for x in np.asarray(a, dtype=float).ravel()]


def _reference(analysis: ModalAnalysis) -> dict:
    spec = analysis.structure.specimen
    ref = getattr(spec, "reference", None)
    if ref is None:
        return {}
    out = {
        k: getattr(ref, k)
        for k in ("J_p", "H_cg", "alpha_cg", "p_l")
        if getattr(ref, k) is not None
    }
    if ref.full_contact_freq_hz:
        out["full_contact_freq_hz"] = list(ref.full_contact_freq_hz)
    if ref.rocking_freq_hz:
        out["rocking_freq_hz"] = list(ref.rocking_freq_hz)
    if ref.source:
        out["source"] = ref.source
    return out


def _derived_comparison(derived: dict, ref: dict) -> dict:
    rows = {}
    for key in ("J_p", "H_cg", "alpha_cg", "p_l"):
        if key in ref:
            unit = printed_unit(ref[key])
            diff = derived[key] - ref[key]
            decimals = max(0, -int(round(np.log10(unit))))
            rows[key] = {
                "computed": derived[key],
                "published": ref[key],
                "difference": diff,
                "printed_unit": unit,
                "agrees": bool(abs(diff) <= unit * (1 + 1e-9)),
                "rounds_to_published": bool(round(derived[key], decimals) == ref[key]),
            }
    return rows


def _freq_comparison(table, paper: list) -> list[dict]:
    """Computed vs published frequency of modes 1, 2, ... (by mode number)."""
    rows = []
    for k, p in enumerate(paper):
        hit = table[table["mode"] == k + 1]
        if len(hit):
            f = float(hit["freq_hz"].iloc[0])
            rows.append(
                {
                    "mode": k + 1,
                    "kind": str(hit["kind"].iloc[0]),
                    "computed_hz": f,
                    "published_hz": float(p),
                    "difference_pct": float(100.0 * (f - p) / p),
                }
            )
    return rows


def _phase_info(modes, idx: np.ndarray) -> dict:
    """JSON block of one phase: underdamped modes, then the overdamped ones."""
    out = {
        "freq_hz": _floats(modes.freq_hz),
        "damping": _floats(modes.damping),
        "mode": [int(j) for j in modes.mode],
        "participation": _floats(modes.participation),
        "undamped_freq_hz": _floats(modes.undamped_omega / (2 * np.pi)),
    }
    od = modes.overdamped_shapes
    out["overdamped"] = {
        "mode": [int(j) for j in modes.overdamped_mode],
        "freq_hz": _floats(modes.overdamped_freq_hz),
        "damping": _floats(modes.overdamped_damping),
        "eigenvalues": [_floats(r) for r in modes.overdamped_eigenvalues],
        "participation": _floats(modes.overdamped_participation),
        "shapes": [_floats(c) for c in od[idx].T],
    }
    if modes.phase == "rocking":
        out["overdamped"]["rocking_part"] = _floats(od[-1])
    return out


def summary(analysis: ModalAnalysis, measured: MeasuredShapes | None = None) -> dict:
    """JSON-ready summary of an analysis (SI units, frequencies in Hz as named).

    Keys: ``specimen``, ``derived``, ``full_contact``, ``rocking``,
    ``mac_full_vs_compound``, ``reference``, ``comparison``, ``shapes`` and,
    with `measured`, ``measured``. Each phase lists its underdamped modes
    (``freq_hz``, ``damping``, ``mode``: their mode numbers, ascending in
    frequency) and, under ``overdamped``, the modes whose eigenvalue couple is
    real (``mode``, ``freq_hz`` = √(λ1 λ2)/2π, ``damping`` ≥ 1, ``eigenvalues``
    [λ1, λ2] in rad/s, ``shapes`` at the shape nodes). Shapes follow the rule of
    `modal.shapes`, the same numbers as the figures.
    """
    s = analysis.structure
    derived = s.derived()
    ref = _reference(analysis)
    fc, rk = analysis.full_contact, analysis.rocking
    fct, rkt = fc.to_pandas(), rk.to_pandas()
    compound = analysis.compound_shapes()
    idx = np.asarray(analysis.shape_nodes) - 1
    rocking = _phase_info(rk, idx)
    rocking["rocking_eigenvalues"] = _floats(analysis.rocking_eigenvalues)
    rocking["rocking_eigenvalue_vs_p_l_pct"] = float(
        100.0 * (analysis.rocking_eigenvalues[0] - s.p_l) / s.p_l
    )
    out = {
        "specimen": s.name,
        "derived": {k: float(v) for k, v in derived.items()},
        "full_contact": _phase_info(fc, idx),
        "rocking": rocking,
        "mac_full_vs_compound": _floats(np.diag(analysis.mac_full_vs_compound())),
        "mac_full_vs_elastic": _floats(np.diag(analysis.mac_full_vs_elastic())),
        "reference": ref,
        "comparison": {
            "derived": _derived_comparison(derived, ref),
            "full_contact_freq": _freq_comparison(fct, ref.get("full_contact_freq_hz", [])),
            "rocking_freq": _freq_comparison(rkt, ref.get("rocking_freq_hz", [])),
        },
        "shapes": {
            "nodes": list(analysis.shape_nodes),
            "heights_m": _floats(analysis.heights),
            "full_contact": [_floats(c) for c in analysis.full_contact_shapes().T],
            "elastic": [_floats(c) for c in analysis.elastic_shapes().T],
            "rocking_part": _floats(analysis.rocking_parts()),
            "compound": [_floats(c) for c in compound.T],
            "compound_nodal_points_m": [
                _floats(nodal_points(analysis.heights, c)) for c in compound.T
            ],
        },
    }
    if ref.get("full_contact_freq_hz") and s.specimen is not None:
        stiff = analyse(column(s.specimen, E_s=_E_SENSITIVITY), analysis.shape_nodes)
        out["comparison"]["E_s_210GPa"] = {
            "full_contact_freq": _freq_comparison(
                stiff.full_contact.to_pandas(), ref["full_contact_freq_hz"]
            ),
            "rocking_freq": _freq_comparison(
                stiff.rocking.to_pandas(), ref.get("rocking_freq_hz", [])
            ),
        }
    if measured is not None:
        out["measured"] = measured_comparison(analysis, measured)
    return out


def measured_comparison(analysis: ModalAnalysis, measured: MeasuredShapes) -> dict:
    """MAC of measured shapes against the model's compound and full-contact shapes."""

    s = analysis.structure
    bad = [i for i in measured.nodes if not 1 <= i <= s.n]
    if bad:
        raise ModalError(
            f"{measured.source}: column `node` holds {bad}, outside the model's nodes 1..{s.n}"
        )
    sub = analyse(s, measured.nodes)
    out = {
        "source": measured.source,
        "nodes": list(measured.nodes),
        "modes": list(measured.names),
        "mac_vs_compound": [_floats(r) for r in sub.mac_measured(measured.shapes, "rocking")],
        "mac_vs_full_contact": [
            _floats(r) for r in sub.mac_measured(measured.shapes, "full_contact")
        ],
    }
    if measured.freq_hz is not None:
        out["freq_hz"] = _floats(measured.freq_hz)
    return out


def _table(header: list[str], rows: list[list]) -> str:
    def fmt(x):
        if isinstance(x, bool):
            return "yes" if x else "**NO**"
        if isinstance(x, float):
            return f"{x:.4g}"
        return str(x)

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(fmt(x) for x in r) + " |" for r in rows]
    return "\n".join(lines)


def _mac_table(mat, row_name: str, col_name: str) -> str:
    m = np.asarray(mat)
    header = [f"{row_name} \\ {col_name}"] + [f"{col_name}{j + 1}" for j in range(m.shape[1])]
    return _table(
        header, [[f"{row_name}{i + 1}"] + [f"{v:.3f}" for v in r] for i, r in enumerate(m)]
    )


_NAMES = {"J_p": "J_p (kg m²)", "H_cg": "H_cg (m)", "alpha_cg": "α_cg (rad)", "p_l": "p_l (rad/s)"}
_MAC_MODES = 10  # modes shown in the Markdown MAC matrices (the JSON has every mode)
#: Below this participation (`PhaseModes.participation`) the report flags a mode as mixed.
MIXED_PARTICIPATION = 0.9


def _derived_section(info: dict) -> list[str]:
    comp = info["comparison"]
    rows = [
        [
            _NAMES[k],
            v["computed"],
            v["published"],
            v["difference"],
            v["agrees"],
            v["rounds_to_published"],
        ]
        for k, v in comp["derived"].items()
    ]
    rows.insert(0, ["m_t (kg)", info["derived"]["m_t"], "–", "–", "–", "–"])
    parts = [
        "## Derived parameters",
        "",
        _table(
            [
                "quantity",
                "computed",
                "published",
                "difference",
                "within one unit of the last printed digit",
                "rounds to it",
            ],
            rows,
        ),
    ]
    mism = [_NAMES[k] for k, v in comp["derived"].items() if not v["agrees"]]
    if mism:
        parts += [
            "",
            f"**Mismatch:** the published {', '.join(mism)} disagree with the values "
            "computed from this specimen's own H and M. The computed values are used; the "
            "published ones are shown, not adopted.",
        ]
    return parts


def _mode_rows(table, ref_rows: list[dict]) -> list[list]:
    ref = {r["mode"]: r for r in ref_rows}
    return [
        [
            int(r.mode),
            r.kind,
            float(r.freq_hz),
            float(r.damping),
            ref[r.mode]["published_hz"] if r.mode in ref else "–",
            f"{ref[r.mode]['difference_pct']:+.2f} %" if r.mode in ref else "–",
        ]
        for r in table.itertuples()
    ]


def _modes_section(analysis: ModalAnalysis, info: dict) -> list[str]:
    comp = info["comparison"]
    fct, rkt = analysis.full_contact.to_pandas(), analysis.rocking.to_pandas()
    hdr = ["mode", "kind", "frequency (Hz)", "damping ζ", "paper (Hz)", "difference"]
    parts = [
        "## Full-contact vibration modes",
        "",
        _table(hdr, _mode_rows(fct, comp["full_contact_freq"])),
        "",
        "## Uplifted (rocking-phase) vibration modes",
        "",
        "Damped state-space (Foss) solution, paper 001 Eqs 24–25.",
        "",
        _table(hdr, _mode_rows(rkt, comp["rocking_freq"])),
    ]
    n = min(3, len(fct))
    ratio = [f"mode {k + 1}: {rkt.freq_hz[k] / fct.freq_hz[k]:.3f}" for k in range(n)]
    parts += [
        "",
        "Modes are numbered by the undamped mode they belong to. Uplifted / "
        "full-contact frequency ratio: " + ", ".join(ratio) + ".",
    ]
    mixed = [
        f"{label} mode {r.mode} ({100 * r.participation:.0f} %)"
        for label, t in (("full-contact", fct), ("uplifted", rkt))
        for r in t.itertuples()
        if r.participation < MIXED_PARTICIPATION
    ]
    if mixed:
        parts += [
            "",
            "**Mixed modes:** damping couples these modes strongly; the share of the "
            "undamped mode they are numbered after in their eigenvectors is "
            + ", ".join(mixed)
            + ". Their numbering is the best assignment, not a "
            "one-to-one match.",
        ]
    return parts + _overdamped_section(info)


def _overdamped_section(info: dict) -> list[str]:
    rows = [
        [label, j, f, z, f"{l1:.6g}", f"{l2:.6g}"]
        for label, key in (("full contact", "full_contact"), ("uplifted", "rocking"))
        for j, f, z, (l1, l2) in zip(
            *(info[key]["overdamped"][k] for k in ("mode", "freq_hz", "damping", "eigenvalues"))
        )
    ]
    if not rows:
        return []
    return [
        "",
        "## Overdamped modes",
        "",
        "These modes do not oscillate: their eigenvalue couple is real, λ1,2 = −ζω ± ω√(ζ² − 1). "
        "Rayleigh damping grows with frequency, so a column's high modes are overdamped. "
        "ω = √(λ1 λ2) and ζ = −(λ1 + λ2)/(2ω) ≥ 1 (Eq 25 read for a real couple); each couple "
        "is paired with the undamped mode its eigenvectors resemble most (`modal.pairing`). "
        "Their shapes are in the JSON report.",
        "",
        _table(["phase", "mode", "ω/2π (Hz)", "damping ζ", "λ1 (rad/s)", "λ2 (rad/s)"], rows),
    ]


def _rocking_section(info: dict) -> list[str]:
    rk, comp = info["rocking"], info["comparison"]
    parts = [
        "## Rocking mode",
        "",
        f"Real eigenvalue pair: {rk['rocking_eigenvalues'][0]:+.5f} / "
        f"{rk['rocking_eigenvalues'][1]:+.5f} rad/s; p_l (Eq 6) = {info['derived']['p_l']:.5f} "
        f"rad/s (difference {rk['rocking_eigenvalue_vs_p_l_pct']:+.3f} %).",
    ]
    if "E_s_210GPa" in comp:
        sens = comp["E_s_210GPa"]
        txt = ", ".join(
            f"{r['computed_hz']:.2f} Hz vs {r['published_hz']} ({r['difference_pct']:+.2f} %)"
            for r in sens["full_contact_freq"] + sens["rocking_freq"]
        )
        parts += [
            "",
            "## Sensitivity: E_s = 210 GPa",
            "",
            "The literal Table 1 inputs (E_s = 200 GPa) are used above. With E_s = 210 GPa "
            f"(full contact, then uplifted): {txt}.",
        ]
    return parts


def _mac_section(analysis: ModalAnalysis) -> list[str]:
    k = _MAC_MODES
    n = analysis.structure.n
    note = (
        f" First {k} of {n} modes; the JSON report lists the diagonal for every mode."
        if n > k
        else ""
    )
    return [
        "## MAC",
        "",
        "Full-contact shapes v_n (rows) vs uplifted compound shapes "
        f"v_c = v_t + H v_r (columns).{note}",
        "",
        _mac_table(analysis.mac_full_vs_compound()[:k, :k], "n", "c"),
        "",
        f"Full-contact shapes v_n (rows) vs uplifted elastic parts v_t (columns).{note}",
        "",
        _mac_table(analysis.mac_full_vs_elastic()[:k, :k], "n", "t"),
    ]


def _shapes_section(info: dict) -> list[str]:
    sh = info["shapes"]
    k = min(3, len(sh["compound"]))
    hdr = ["node", "height (m)"] + [f"v_c{j + 1}" for j in range(k)]
    rows = [
        [n, h] + [sh["compound"][j][i] for j in range(k)]
        for i, (n, h) in enumerate(zip(sh["nodes"], sh["heights_m"]))
    ]
    nps = sh["compound_nodal_points_m"]
    return [
        "## Compound shapes",
        "",
        "Scale: the elastic part over the shape nodes has unit Euclidean norm; v_r keeps the "
        "same scale. Sign: a full-contact shape's largest component is positive; an uplifted "
        "mode takes the sign that makes whichever of v_t and v_c is closer to v_n (larger MAC) "
        "correlate positively with it (`modal.shapes`). The figures draw these numbers.",
        "",
        _table(hdr, rows),
        "",
        "Sign changes of compound shapes (m): "
        + "; ".join(
            f"mode {j + 1}: " + (", ".join(f"{x:.3f}" for x in nps[j]) or "none") for j in range(k)
        )
        + ".",
    ]


def markdown(analysis: ModalAnalysis, info: dict, figures: list[str] = ()) -> str:
    """The Markdown report of one analysis, from its `summary` dict.

    With an ``frf`` block in `info` (`write_report` with ``frf=True``), a
    "Frequency response" section (`modal.frf_report`) shows its figure.
    """
    s = analysis.structure
    parts = [
        f"# Modal report — {s.name}",
        "",
        f"Paper 001 (Acikgoz & DeJong 2016), Sections 3 and 4.2. Specimen source: "
        f"{getattr(s.specimen, 'source', '') or 'user file'}. N = {s.n} nodes; shapes at nodes "
        f"{', '.join(map(str, analysis.shape_nodes))}.",
        "",
    ]
    for section in (
        _derived_section(info),
        _modes_section(analysis, info),
        _rocking_section(info),
        _mac_section(analysis),
        _shapes_section(info),
    ):
        parts += section + [""]
    if "measured" in info:
        meas = info["measured"]
        parts += [
            "## Measured shapes",
            "",
            f"From `{meas['source']}` at nodes "
            f"{meas['nodes']}. MAC, measured (rows) vs compound uplifted shapes (columns):",
            "",
            _mac_table(meas["mac_vs_compound"], "m", "c"),
            "",
        ]
    if "frf" in info:
        from .frf_report import frf_markdown

        parts += frf_markdown(info["frf"]) + [""]
    shown = {info["frf"]["figure"]} if "frf" in info else set()
    figures = [f for f in figures if Path(f).name not in shown]
    if figures:
        parts += ["## Figures", ""] + [f"![{Path(f).stem}]({Path(f).name})" for f in figures]
    return "\n".join(parts).rstrip("\n") + "\n"


def write_report(
    analysis: ModalAnalysis,
    out_dir: str | Path,
    measured: MeasuredShapes | None = None,
    figures: bool = True,
    *,
    frf: bool = False,
    frf_sensors=None,
    measured_frf: MeasuredFRF | None = None,
    frf_source: str | None = None,
) -> dict:
    """Write ``<name>_modal.md``, ``<name>_modal.json`` and figures into `out_dir`.

    Parameters
    ----------
    analysis : ModalAnalysis
    out_dir : str or Path
    measured : MeasuredShapes, optional
        Measured shapes, for MAC.
    figures : bool, optional
        Write the PNG figures.
    frf : bool, optional
        Add the frequency responses of both phases: ``<name>_frf.png``
        (`modal.frf_plots.frf_figure`), a "Frequency response" section and an
        ``frf`` block (`modal.frf_report.frf_summary`). Needs `figures`.
    frf_sensors : sequence of int or str, optional
        Nodes or sensor names drawn (default: the specimen's named sensors).
    measured_frf : MeasuredFRF, optional
        A measured H1 estimate to overlay (rows named ``a<node>``), e.g. from
        `modal.measured_frf.full_contact_h1`.
    frf_source : str, optional
        Where `measured_frf` came from (a trace's file name), for the report.

    Returns
    -------
    dict
        The summary (the JSON content).
    """
    out = Path(out_dir)
    if (frf or measured_frf is not None) and not figures:
        raise ModalError("`frf` draws a figure: leave `figures` True, or drop `frf`")
    out.mkdir(parents=True, exist_ok=True)
    info = summary(analysis, measured)
    files = []
    if figures:
        from .plots import plot_eigenvalues, plot_shapes

        files = [
            plot_eigenvalues(analysis, out / f"{analysis.structure.name}_eigenvalues.png"),
            plot_shapes(analysis, out / f"{analysis.structure.name}_shapes.png"),
        ]
    if frf or measured_frf is not None:
        from .frf_plots import plot_frf
        from .frf_report import frf_summary

        path = plot_frf(
            analysis, out / f"{analysis.structure.name}_frf.png", frf_sensors, measured_frf
        )
        files.append(path)
        info["frf"] = frf_summary(analysis, path.name, frf_sensors, measured_frf, frf_source)
    stem = out / f"{analysis.structure.name}_modal"
    stem.with_suffix(".md").write_text(
        markdown(analysis, info, [str(f) for f in files]), encoding="utf-8"
    )
    stem.with_suffix(".json").write_text(json.dumps(info, indent=2), encoding="utf-8")
    return info
