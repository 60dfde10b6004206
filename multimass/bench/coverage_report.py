"""Tables and figures of the identification coverage benchmark (`multimass.bench.coverage`).

`write_report` reads ``results.jsonl`` and writes ``estimates.csv`` (every estimate
with its truth, error and interval; ``estimates.parquet`` too when pyarrow is
installed), ``cases.csv`` (every case's hidden parameters, statuses and times),
``summary.json``, ``coverage.md`` and three figures: ``coverage_error_vs_std.png``
(``|error|`` against the reported std), ``coverage_per_quantity.png`` (the share of the
95 % intervals that hold the truth) and ``coverage_error_vs_cp.png`` (the errors of
the coefficients of restitution against the drawn C_p over Table 2's).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from .coverage import read_results, read_runs
from .coverage_stats import QUANTITIES, add_errors, summarise

__all__ = ["write_report", "tables", "markdown"]

_ESTIMATORS = ("restitution", "calibrate")
_TRUSTED = ("estimated", "converged")  # run statuses that claim every parameter is fixed


def tables(cases: list[dict]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(estimates with errors, one row per case) from the cases of ``results.jsonl``."""
    case_rows = [c["case"] for c in cases]
    est = pd.DataFrame([r for c in cases for r in c["rows"]])
    meta = pd.DataFrame(case_rows)
    if est.empty:
        return est, meta
    if "kind" in est:  # table motion runs on the trace's clock: no offset to compare
        est = est[~((est["quantity"] == "t_offset") & (est["kind"] == "table"))]
    est = add_errors(est.reset_index(drop=True))
    keep = ["case", "cp", "cp_table", "fs", "noise", "sigma_r", "zeta1", "zeta2"]
    drawn = meta[[k for k in keep if k in meta]].rename(
        columns={k: f"drawn_{k}" for k in keep if k != "case"}
    )
    est = est.merge(drawn, on="case", how="left")
    est["cp_ratio"] = est["drawn_cp"] / est["drawn_cp_table"]
    status = {}  # (case, estimator) → the run's status ("estimated", "ill-posed", ...)
    for name in _ESTIMATORS:
        if f"{name}_status" in meta:
            status |= {(c, name): st for c, st in zip(meta["case"], meta[f"{name}_status"])}
    est["run_status"] = [status.get(k) for k in zip(est["case"], est["estimator"])]
    return est, meta


def _fmt(x, q: str | None = None, kind: str = "err") -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if kind == "share":
        return f"{100 * x:.0f} %"
    if q is not None and QUANTITIES.get(q) and QUANTITIES[q].relative:
        return f"{100 * x:.1f} %"
    return f"{x:.2g}" if abs(x) < 1e-3 else f"{x:.4f}"


def _band(r) -> str:
    """A coverage's Clopper–Pearson interval, " [lo–hi %]" (empty without one)."""
    lo, hi = r.get("coverage_lo", math.nan), r.get("coverage_hi", math.nan)
    if lo is None or hi is None or math.isnan(lo) or math.isnan(hi):
        return ""
    return f" [{100 * lo:.0f}–{100 * hi:.0f} %]"


def markdown(summary: pd.DataFrame, meta: pd.DataFrame, facts: dict) -> str:
    """The Markdown page body: one table per estimator, then the cases' facts."""
    lines = []
    for est in _ESTIMATORS:
        part = summary[summary["estimator"] == est] if not summary.empty else summary
        if part.empty:
            continue
        lines += [
            f"### `{est}`",
            "",
            "| specimen | quantity | n | median \\|err\\| | 95th pct | max | within "
            "threshold | n estimated, with a 95 % interval | coverage of the 95 % interval "
            "[its 95 % binomial interval] "
            "| coverage (nominal truth) | ill-posed | ill-posed: truth within the explored "
            "range |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for _, r in part.iterrows():
            q = r["quantity"]
            qd = QUANTITIES.get(q)
            thr = "" if qd is None or qd.threshold is None else (
                f" (≤ {100 * qd.threshold:.0f} %)" if qd.relative else f" (≤ {qd.threshold:g})"
            )  # fmt: skip
            lines.append(
                f"| {r['specimen']} | {qd.label if qd else q} | {r['n']} | {_fmt(r['median'], q)} "
                f"| {_fmt(r['p95'], q)} | {_fmt(r['max'], q)} | {_fmt(r['within'], kind='share')}"
                f"{thr if not math.isnan(r['within']) else ''} | {r['n_interval']} "
                f"| {_fmt(r['coverage'], kind='share')}{_band(r)} "
                f"| {_fmt(r['coverage_nominal'], kind='share')} | {r.get('n_ill_posed', 0)} "
                f"| {_fmt(r.get('coverage_ill_posed', math.nan), kind='share')} |"
            )
        lines.append("")
    lines += ["### Cases", ""]
    for key, value in facts.items():
        lines.append(f"- {key}: {value}")
    return "\n".join(lines) + "\n"


def _facts(meta: pd.DataFrame, est: pd.DataFrame) -> dict:
    """Counts, failures and times of the cases."""
    out = {"cases": int(len(meta))}
    if meta.empty:
        return out
    out["cases per specimen"] = ", ".join(
        f"{k} {v}" for k, v in meta["specimen"].value_counts().sort_index().items()
    )
    out["table-motion cases"] = int((meta["kind"] == "table").sum())
    if "error" in meta:
        bad = meta["error"].dropna()
        out["cases whose generation or run failed"] = int(bad.size)
    for name in _ESTIMATORS:
        col = f"{name}_status"
        if col not in meta:
            continue
        st = meta[col].dropna()
        if st.empty:
            continue
        counts = st.map(lambda s: "error" if str(s).startswith("error") else s).value_counts()
        out[f"{name} runs"] = (
            f"{int(st.size)} (" + ", ".join(f"{k} {v}" for k, v in counts.items()) + ")"
        )
        secs = meta[f"{name}_s"].dropna()
        out[f"{name} time per trace (s)"] = (
            f"median {secs.median():.1f}, max {secs.max():.1f}, total {secs.sum():.0f}"
        )
        errs = st[st.astype(str).str.startswith("error")]
        for msg, k in errs.map(lambda s: s[7:90]).value_counts().head(5).items():
            out[f"{name} refused ({k}×)"] = msg
    return out


def write_report(out, facts: dict | None = None) -> dict:
    """Write the tables, the summary and the figures of the results in `out`; the
    summary (JSON-ready)."""
    out = Path(out)
    cases = read_results(out)
    est, meta = tables(cases)
    summary = summarise(est) if not est.empty else pd.DataFrame()
    trusted = pd.DataFrame()  # the runs whose result says every parameter was estimated
    if not est.empty:
        ok = est[est["run_status"].isin(_TRUSTED)]
        trusted = summarise(ok, by_specimen=False) if not ok.empty else trusted
        est.to_csv(out / "estimates.csv", index=False)
        try:
            est.to_parquet(out / "estimates.parquet", index=False)
        except ImportError:  # pyarrow / fastparquet not installed: the CSV holds it all
            pass
    meta.to_csv(out / "cases.csv", index=False)
    all_facts = {**_facts(meta, est), **(facts or {})}
    for i, run in enumerate(read_runs(out)):
        all_facts[f"run {i + 1}"] = (
            f"started {run['started_utc']}, {run['cases_run']} cases, {run['workers']} "
            f"workers, {run['wall_time_s']:.0f} s wall"
            + (f", commit {run['commit']}" if run.get("commit") else "")
        )
    charts = figures(est, out) if not est.empty else []
    result = {
        "facts": all_facts,
        "summary": json.loads(summary.to_json(orient="records")) if not summary.empty else [],
        "summary_runs_not_ill_posed": json.loads(trusted.to_json(orient="records"))
        if not trusted.empty
        else [],
        "charts": charts,
    }
    (out / "summary.json").write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    text = markdown(summary, meta, all_facts)
    if not trusted.empty:
        part = markdown(trusted, meta.iloc[0:0], {}).split("### Cases")[0]
        text += (
            "\n## Only the runs whose result says every parameter was estimated\n\n"
            "(status "
            + ", ".join(_TRUSTED)
            + "; the runs that said ill-posed left out)\n\n"
            + part.replace("### `", "### `", 1)
        )
    (out / "coverage.md").write_text(text, encoding="utf-8")
    return result


# ------------------------------------------------------------------------------- figures
def figures(est: pd.DataFrame, out: Path) -> list[str]:
    """The three figures; their file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = []
    for fn, name in ((_fig_error_vs_std, "coverage_error_vs_std.png"),
                     (_fig_coverage, "coverage_per_quantity.png"),
                     (_fig_error_vs_cp, "coverage_error_vs_cp.png")):  # fmt: skip
        fig = fn(est, plt)
        fig.savefig(out / name, dpi=110)
        plt.close(fig)
        names.append(name)
    return names


def _present(est: pd.DataFrame) -> list[str]:
    return [e for e in _ESTIMATORS if (est["estimator"] == e).any()]


def _fig_error_vs_std(est, plt):
    ests = _present(est)
    fig, axes = plt.subplots(1, len(ests), figsize=(6.2 * len(ests), 5.0), squeeze=False)
    for ax, name in zip(axes[0], ests):
        d = est[(est["estimator"] == name) & np.isfinite(est["abs_err"])]
        huge = d["std_in_units"] > 1e3  # an infinite std, or one beyond any meaning
        n_inf = int(huge.sum())
        d = d[~huge & (d["std_in_units"] > 0)]
        for i, (q, g) in enumerate(d.groupby("quantity", sort=False)):
            ax.scatter(g["std_in_units"], g["abs_err"].clip(lower=1e-7), s=10, alpha=0.6,
                       label=QUANTITIES[q].label if q in QUANTITIES else q, color=f"C{i}")  # fmt: skip
        if not d.empty:
            both = np.concatenate([d["std_in_units"], d["abs_err"].clip(lower=1e-7)])
            lo, hi = max(both.min(), 1e-7) / 2.0, both.max() * 2.0
            x = np.array([lo, hi])
            ax.plot(x, 1.96 * x, "k--", lw=1, label="|err| = 1.96 std (edge of the 95 % interval)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlim(lo, hi)
            ax.set_ylim(lo, hi)
        ax.set_xlabel("reported std (relative for C_p, ζ)")
        ax.set_ylabel("|error| (relative for C_p, ζ)")
        n_none = int((est[(est["estimator"] == name)]["std"].isna()).sum())
        ax.set_title(f"{name}: error against reported std\n(not shown: {n_none} estimates without "
                     f"a std, {n_inf} with one > 1000)", fontsize=10)  # fmt: skip
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def _fig_coverage(est, plt):
    summ = summarise(est)
    ests = _present(est)
    fig, axes = plt.subplots(len(ests), 1, figsize=(11, 3.6 * len(ests)), squeeze=False)
    specs = [s for s in summ["specimen"].unique()]
    for ax, name in zip(axes[:, 0], ests):
        s = summ[summ["estimator"] == name]
        qs = [q for q in QUANTITIES if q in set(s["quantity"])]
        width = 0.8 / max(len(specs), 1)
        for i, q in enumerate(qs):
            if s[s["quantity"] == q]["coverage"].isna().all():
                ax.text(i, 2, "no interval\nreported", ha="center", va="bottom", fontsize=7,
                        color="0.4")  # fmt: skip
                continue
            for j, spec in enumerate(specs):
                r = s[(s["specimen"] == spec) & (s["quantity"] == q)]
                x = i + (j - (len(specs) - 1) / 2) * width
                if r.empty or math.isnan(float(r["coverage"].iloc[0])):
                    continue
                cov = float(r["coverage"].iloc[0])
                ax.bar(x, 100 * cov, width, color=f"C{j}", label=spec)
                ax.text(
                    x, 100 * cov + 1, f"{int(r['n_interval'].iloc[0])}", ha="center", fontsize=6
                )
        ax.axhline(95, color="k", ls="--", lw=1, label="95 % (nominal)")
        ax.axhline(90, color="r", ls=":", lw=1, label="90 % (asked)")
        ax.set_xticks(range(len(qs)))
        ax.set_xticklabels([QUANTITIES[q].label for q in qs], fontsize=8, rotation=15, ha="right")
        ax.set_ylim(0, 118)
        ax.set_ylabel("truth inside the 95 % interval (%)")
        ax.set_title(
            f"{name}: coverage per quantity (numbers: estimates with an interval)", fontsize=10
        )
        handles, labels = ax.get_legend_handles_labels()
        keep = dict(zip(labels, handles))  # one entry per specimen
        ax.legend(keep.values(), keep.keys(), fontsize=7, ncol=len(keep), loc="upper right")
    fig.tight_layout()
    return fig


def _fig_error_vs_cp(est, plt):
    ests = _present(est)
    fig, axes = plt.subplots(2, len(ests), figsize=(6.2 * len(ests), 7.5), squeeze=False)
    for k, name in enumerate(ests):
        d = est[(est["estimator"] == name) & np.isfinite(est["err"])]
        for row, (qs, thr, label) in enumerate(
            ((["r"], 0.015, "per-impact r"),
             (["r_mean_right", "r_mean_left"], 0.01, "corner means r̄_er, r̄_el"))
        ):  # fmt: skip
            ax = axes[row, k]
            g = d[d["quantity"].isin(qs)]
            for j, (spec, gs) in enumerate(g.groupby("specimen")):
                ax.scatter(gs["cp_ratio"], gs["err"], s=10, alpha=0.6, color=f"C{j}", label=spec)
            ax.axhspan(-thr, thr, color="g", alpha=0.12, label=f"±{thr:g} (asked)")
            ax.axvline(1.0, color="k", lw=0.8)
            ax.set_yscale("symlog", linthresh=thr)  # linear within the threshold, log beyond
            top = max(float(g["err"].abs().max()) if not g.empty else 0.0, thr) * 1.6
            ax.set_ylim(-top, top)
            ax.set_xlabel("drawn C_p / Table 2's C_p")
            ax.set_ylabel(f"error of {label} (symlog)")
            ax.set_title(f"{name}: {label}", fontsize=10)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig
