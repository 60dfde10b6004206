"""Compare simulations with a recorded test trace, from Python (paper 001, Section 4.3).

A researcher who has released their column on a shake table loads the recorded θ and
accelerations and overlays simulations with the classical (CIM) and Dirac-delta (DD2)
impact models, to see which calibrates best. Here the "recording" is synthetic, so the
script runs anywhere: an S1 simulation with its own restitution (0.90 at both corners),
sampled at 200 Hz, with a little noise, written to a CSV trace in deg and g.

Run:  python examples/compare_trace.py  (a few seconds)
The same from the shell:  multimass compare S1 TRACE.csv --impact CIM,DD2 --out report/
"""

import tempfile
from pathlib import Path

import numpy as np

import multimass

T_END = 1.5  # s of free rocking (paper 001 Fig 6 shows 6 s; kept short so the example is quick)


def write_synthetic_trace(path: Path) -> Path:
    """A free-release "test" of S1 from 0.11 rad (paper 001, Section 4.3), as a CSV trace."""
    test = multimass.simulate(
        "S1", multimass.FreeRelease(0.11), impact="DD", restitution=0.90, t_end=T_END
    )
    df = test.series
    t = np.arange(0.0, T_END + 1e-9, 0.005)  # a 200 Hz data logger
    rng = np.random.default_rng(1)
    keep = np.r_[np.diff(df.t) > 0, True]  # drop repeated event times
    sample = {c: np.interp(t, df.t[keep], df[c][keep]) for c in ("theta", "a3", "a5")}
    theta_deg = np.degrees(sample["theta"]) + rng.normal(0.0, 0.01, t.size)
    a_A2_g = sample["a3"] / 9.81 + rng.normal(0.0, 0.01, t.size)
    a_A4_g = sample["a5"] / 9.81 + rng.normal(0.0, 0.01, t.size)
    rows = np.column_stack([t, theta_deg, a_A2_g, a_A4_g])
    np.savetxt(
        path,
        rows,
        delimiter=",",
        fmt="%.6g",
        comments="",
        header="t [s],theta [deg],a_A2 [g],a_A4 [g]",
    )
    return path


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        trace = multimass.read_trace(write_synthetic_trace(Path(tmp) / "S1_free_test.csv"))
    s1 = multimass.column("S1")
    release = trace.free_release()  # θ0 = the trace's first θ, at rest
    print(
        f"trace: {trace.time.size} samples, {trace.duration:.2f} s, channels "
        f"{', '.join(f'{n} [{u}]' for n, u in trace.units.items())}; "
        f"release from {release.theta0:.4f} rad"
    )
    for impact in ("CIM", "DD2"):
        resp = multimass.simulate(s1, release, impact=impact, t_end=trace.duration)
        metrics = multimass.compare_trace(trace, resp, s1, t_offset=trace.time[0])
        print(f"\n{impact}: {resp.status}, {resp.n_impacts} impacts, {resp.wall_time_s:.2f} s")
        for name, m in metrics.items():
            print(
                f"  {name:<6} RMS error {m.rms_error:8.4g} {m.units:<4} (NRMSE {m.nrmse:6.1%}), "
                f"peak error {m.peak_error_rel:+6.1%}, peak-time shift {m.peak_time_shift_s:+.3f} s"
            )


if __name__ == "__main__":
    main()
