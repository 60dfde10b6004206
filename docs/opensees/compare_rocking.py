"""Rocking side by side: multimass (CIM, DD2) vs the exported OpenSees rocking model.

Writes s1_elcentro.png, s1_release.png, b6m_release.png and numbers.json beside this file.
Run from the repository: `python docs/opensees/compare_rocking.py` (a few minutes).
"""

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass.export import opensees

HERE = Path(__file__).resolve().parent
RECORD = HERE.parents[1].parent / "shared" / "data" / "ground_motions" / "elcentro_1940_NS.dat"


def run_opensees(specimen, record=None, release=None, t_end=4.0):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.py"
        opensees(specimen, "rocking", record, out=path, release=release, t_end=t_end)
        start = time.perf_counter()
        subprocess.run([sys.executable, "model.py"], cwd=tmp, check=True, capture_output=True)
        wall = time.perf_counter() - start
        t, theta = np.loadtxt(Path(tmp) / "theta.out").T
    return t, theta, wall


def peaks(t, theta):
    """|θ| at each local extremum of |θ| between sign changes (half-cycle peaks)."""
    out = []
    sign = np.sign(theta)
    edges = np.flatnonzero(np.diff(sign) != 0)
    bounds = np.concatenate([[0], edges + 1, [theta.size]])
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b > a and np.max(np.abs(theta[a:b])) > 1e-3:
            out.append(float(np.max(np.abs(theta[a:b]))))
    return out


def case(name, specimen, excitation, record=None, release=None, t_end=4.0):
    result = {"case": name}
    fig, ax = plt.subplots(figsize=(8, 3.2))
    for impact in ("CIM", "DD2"):
        start = time.perf_counter()
        r = multimass.simulate(specimen, excitation, impact=impact, t_end=t_end, progress=False)
        result[f"multimass_{impact}_s"] = time.perf_counter() - start
        ax.plot(r.series["t"], r.series["theta"], label=f"multimass {impact}")
        result[f"peaks_{impact}"] = [float(p) for p in r.peaks[:8]]
    t, theta, wall = run_opensees(specimen, record, release, t_end)
    result["opensees_s"] = wall
    result["peaks_opensees"] = peaks(t, theta)[:8]
    ax.plot(t, theta, "k--", lw=1, label="OpenSees (contact springs, ζ_c = 1)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("θ (rad)")
    ax.set_title(name)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / f"{name}.png", dpi=110)
    plt.close(fig)
    return result


def main():
    rec = multimass.read_record(RECORD, units="g", scale=1.1)
    rows = [
        case("s1_release", "S1", multimass.FreeRelease(theta0=0.11), release=0.11, t_end=3.0),
        case("s1_elcentro", "S1", rec, record=rec, t_end=8.0),
        case("b6m_release", "B6M", multimass.FreeRelease(theta0=0.1), release=0.1, t_end=2.0),
    ]
    (HERE / "numbers.json").write_text(json.dumps(rows, indent=1))
    print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
