"""The parts of an exported OpenSeesPy script shared by every phase and kind.

The script's header, the loader (`_runtime.load_opensees`, copied), the ground
motion, the recorders, the analysis and the ``__main__`` block. Each constant the
sections read is written by `multimass.export.opensees` above them.
"""

from __future__ import annotations

__all__ = ["IMPORTS", "GROUND_MOTION", "RECORDERS", "ANALYSIS_LINEAR", "MAIN", "number_list"]

IMPORTS = """
import os
import sys
"""

GROUND_MOTION = '''
def ground_motion(ops):
    """The record as a `Path` time series and a uniform excitation in X.

    RECORD_ACCEL holds the record's samples in m/s^2 (already converted and scaled),
    every RECORD_DT s from RECORD_T0 s; OpenSees interpolates linearly between them and
    gives 0 outside them, as multimass.Record does. Returns the series' tag (None
    without a record).
    """
    if not RECORD_ACCEL:
        return None
    tag = OFFSET + GROUND_SERIES
    ops.timeSeries("Path", tag, "-dt", RECORD_DT, "-values", *RECORD_ACCEL,
                   "-startTime", RECORD_T0)
    ops.pattern("UniformExcitation", tag, 1, "-accel", tag)
    return tag
'''

RECORDERS = '''
def recorders(ops, folder=".", series=None):
    """The channels of multimass.simulate, sampled every OUTPUT_DT s.

    disp.out   t, X of nodes 1..N (m), relative to the ground (u_i + H_i θ while rocking)
    accel.out  t, total X accelerations of nodes 1..N (m/s^2, the ground's added)
    rotation.out  t, rotation of the base (rad, anticlockwise); `theta.out` (t, θ = -it)
    is written from it after the run (`write_theta`).
    """
    nodes = [OFFSET + i for i in range(1, len(HEIGHTS) + 1)]
    every = ("-time", "-precision", 12, "-dT", OUTPUT_DT)
    if nodes:
        ops.recorder("Node", "-file", os.path.join(folder, "disp.out"), *every,
                     "-node", *nodes, "-dof", 1, "disp")
        total = ("-timeSeries", series) if series is not None else ()
        ops.recorder("Node", "-file", os.path.join(folder, "accel.out"), *every, *total,
                     "-node", *nodes, "-dof", 1, "accel")
    ops.recorder("Node", "-file", os.path.join(folder, "rotation.out"), *every,
                 "-node", OFFSET + BASE, "-dof", 3, "disp")


def write_theta(folder="."):
    """theta.out: t, θ (rad), θ > 0 towards the right pivot (paper 001, Fig 1)."""
    with open(os.path.join(folder, "rotation.out")) as src:
        rows = [line.split() for line in src if line.strip()]
    with open(os.path.join(folder, "theta.out"), "w") as dst:
        for t, r in rows:
            dst.write(f"{t} {-float(r)!r}\\n")
'''

ANALYSIS_LINEAR = '''
def analysis(ops):
    """A linear transient analysis: Newmark's average acceleration (gamma = 1/2, beta = 1/4).

    Unconditionally stable and without numerical damping; its period error is about
    (omega dt)^2 / 12, so DT is chosen from the highest frequency of interest (see its
    comment). The rigid links need the Transformation constraint handler.
    """
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 10)
    ops.algorithm("Linear")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def eigenvalues(ops):
    """Undamped eigenvalues omega^2 (rad^2/s^2) of every mode with mass, ascending.

    '-fullGenLapack': the model has as few degrees of freedom with mass as modes
    wanted, too few for the default ARPACK solver, and the uplifted system has one
    negative eigenvalue (the rocking mode, about -p_l^2), which it finds too.
    """
    return sorted(ops.eigen("-fullGenLapack", N_MODES))


def run(ops, folder=".", t_end=None, dt=None):
    """Integrate to `t_end` (s) in steps `dt` (s); returns 0 on success."""
    t_end = T_END if t_end is None else t_end
    dt = DT if dt is None else dt
    return ops.analyze(int(round(t_end / dt)), dt)
'''

MAIN = """
if __name__ == "__main__":
    ops = load_opensees()
    if ops is None:
        sys.exit("OpenSeesPy is not installed: pip install openseespy")
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    build(ops)
    start(ops)
    report(ops)
    series = ground_motion(ops)
    recorders(ops, ".", series)
    status = run(ops)
    ops.wipe()  # closes the recorders' files
    write_theta(".")
    print(f"{NAME} ({PHASE}): {'completed' if status == 0 else 'failed'} to t = {T_END} s; "
          "wrote theta.out, disp.out, accel.out")
    sys.exit(0 if status == 0 else 1)
"""


def number_list(values, per_line: int = 6, indent: str = "    ") -> str:
    """A Python list literal of floats, `per_line` a line, round-trip exact (repr)."""
    items = [repr(float(v)) for v in values]
    if len(items) <= per_line:
        return "[" + ", ".join(items) + "]"
    lines = [
        indent + ", ".join(items[k : k + per_line]) + "," for k in range(0, len(items), per_line)
    ]
    return "[\n" + "\n".join(lines) + "\n]"
