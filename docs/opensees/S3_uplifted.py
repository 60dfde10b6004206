"""OpenSeesPy model of specimen S3, phase uplifted.

Phase: linear, rocking on the right pivot, linearised about θ = 0 (paper 001, Eqs 19-20).

Specimen: S3. Masses at mid-height and top, heavier top (mass arrangement S3).
Source: paper 001, Table 1.
Ground motion: none (free vibration).
Exported by multimass (multimass.export.opensees).

Units: SI throughout: m, kg, s, N, rad (N m, N/m, N m/rad, Pa, kg m^2, m/s^2).
Axes: X lateral, positive towards the right pivot; Y up. theta > 0 rocks on the right
pivot (paper 001, Fig 1); OpenSees rotations are anticlockwise, so theta = -rotation.

Run it: `python model.py` builds the model, prints its modes (linear phases), runs the
analysis and writes theta.out, disp.out and accel.out here. To put the model into a
larger one, import this file and call `build(ops)` in your own domain (2-D, 3 degrees
of freedom per node); set OFFSET first if your tags collide with these.
"""


import os
import sys


# ---------------------------------------------------------------- OpenSeesPy
# multimass.export._runtime.load_opensees, copied: the Linux wheel's bundled BLAS
# must be loaded before OpenSeesPy imports on machines without a system BLAS.

def load_opensees():
    """Import and return ``openseespy.opensees``, loading the wheel's bundled BLAS first.

    Returns None if OpenSeesPy is not installed; raises ImportError if it is
    installed but cannot be loaded.
    """
    import ctypes
    import importlib
    import importlib.util
    import os
    import sys

    if importlib.util.find_spec("openseespy") is None:
        return None
    if sys.platform.startswith("linux"):
        spec = importlib.util.find_spec("openseespylinux")
        for folder in spec.submodule_search_locations if spec else ():
            lib = os.path.join(folder, "lib")
            # dependencies first: Fortran run-time, then BLAS, then LAPACK (needs BLAS)
            for name in ("libquadmath.so.0", "libgfortran.so.4", "libblas.so.3", "liblapack.so.3"):
                path = os.path.join(lib, name)
                if os.path.exists(path):
                    ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    try:
        return importlib.import_module("openseespy.opensees")
    except RuntimeError as exc:  # the package wraps every load failure in a RuntimeError
        raise ImportError(f"OpenSeesPy is installed but does not load: {exc}") from exc

# ---------------------------------------------------------------- the specimen
NAME = 'S3'
PHASE = 'uplifted'
OFFSET = 0  # added to every tag below
G = 9.81  # m/s^2
B = 0.305  # m, half the distance between the pivots
HEIGHTS = [0.06, 0.49, 0.93, 1.43, 1.93]  # m, nodes 1..N above the base
MASSES = [77.3, 6.2, 48.1, 8.2, 86.2]  # kg, lumped at nodes 1..N
M0 = 0.0  # kg, base (node 0)
J0 = 10.0  # kg m^2, base rotary inertia about its centre of mass
H0 = 0.0  # m, height of the base's centre of mass above the pivots
E_S = 200000000000.0  # Pa, Young's modulus
I_S = 1.833e-06  # m^4, second moment of area
K_FP = 500000000.0  # N/m, horizontal spring, base to node 1
K_ROT = 2000000.0  # N m/rad, rotational spring, base to node 1
ZETA_1, ZETA_2 = 0.005, 0.015  # fractions of critical, full-contact modes 1 and 2
# rad/s, undamped full-contact modes 1 and 2
OMEGA_1, OMEGA_2 = 37.06676670423307, 313.20690744856046
RAYLEIGH_A0 = 0.24246249569492145  # 1/s, C = a0 M + a1 K (multimass.model.damping)
RAYLEIGH_A1 = 9.331170698514537e-05  # s
# axial area: inextensible in the linear phases (Y fixed); while rocking, stiff
AXIAL_AREA = 0.11896160086533264  # m^2

# ---------------------------------------------------------------- tags
# OFFSET is added to each: node i (1..N) and the beam from node i to i + 1 are i
BASE = 1000
PIVOT = 1001
BASE_SPRING = 1000
FRAME = 2000
ANCHOR = 3000
GRAVITY_NEG = 3000
GRAVITY_POS = 4000
DASHPOT = 5000
GROUND_SERIES = 2
GRAVITY_SERIES = 1

# ---------------------------------------------------------------- the motion
RECORD_DT = None
RECORD_T0 = 0.0
RECORD_ACCEL = []  # no ground motion
T_END = 1.0  # s, end of the analysis
DT = 0.00014285714285714287  # s, analysis step (multimass.export.default_dt)
OUTPUT_DT = 0.001  # s, recorders' step
N_MODES = 6  # modes with mass


def nodes_and_masses(ops):
    """Nodes 1..N at the specimen heights with their lumped masses, and the base (node 0).

    Every node moves in X (lateral, positive towards the right pivot) and rotates;
    Y is fixed on nodes 1..N: the column is inextensible (multimass's model has no
    axial degree of freedom), so the beams' axial stiffness never acts.
    """
    for i, (h, m) in enumerate(zip(HEIGHTS, MASSES), start=1):
        ops.node(OFFSET + i, 0.0, h)  # m
        ops.mass(OFFSET + i, m, m, 0.0)  # kg; lumped masses carry no rotary inertia
        ops.fix(OFFSET + i, 0, 1, 0)
        # the base's frame point at the height of node i (the reference of u_i)
        ops.node(OFFSET + FRAME + i, 0.0, h)
    ops.node(OFFSET + BASE, 0.0, 0.0)
    ops.mass(OFFSET + BASE, M0, M0, J0)  # kg, kg, kg m^2


def elements(ops):
    """Elastic beam-columns E_s I_s between consecutive nodes (paper 001, Eq 1)."""
    ops.geomTransf("Linear", OFFSET + 1)
    for i in range(1, len(HEIGHTS)):
        # the area only sets the axial stiffness, which the fixed Y degrees of freedom
        # never strain; it is the bending stiffness E_S * I_S that acts
        ops.element(
            "elasticBeamColumn", OFFSET + i, OFFSET + i, OFFSET + i + 1,
            AXIAL_AREA, E_S, I_S, OFFSET + 1,
        )


def base(ops):
    """Uplifted on the right pivot: the rigid base rotates about the pivot (θ > 0).

    The pivot node sits at (B, 0), pinned; its rotation is -θ (OpenSees measures
    rotations anticlockwise, paper 001 measures θ > 0 towards the right pivot). The
    base (node 0, mass M0, inertia J0) and the frame points under nodes 1..N follow it
    as a rigid body (rigidLink "beam", linearised about θ = 0 as Eqs 19-20 are).
    Nodes 1..N rise by B θ with the base in the linearised equations; their Y is fixed
    here, so that vertical inertia, sum(m_i) B^2, is lumped on the pivot's rotation.
    """
    ops.node(OFFSET + PIVOT, B, 0.0)
    ops.fix(OFFSET + PIVOT, 1, 1, 0)
    ops.mass(OFFSET + PIVOT, 0.0, 0.0, sum(MASSES) * B**2)  # kg m^2
    ops.rigidLink("beam", OFFSET + PIVOT, OFFSET + BASE)
    for i in range(1, len(HEIGHTS) + 1):
        ops.rigidLink("beam", OFFSET + PIVOT, OFFSET + FRAME + i)
    base_springs(ops)


def base_springs(ops):
    """K_FP on X and K_ROT on the rotation between the base and node 1 (N/m, N m/rad)."""
    ops.uniaxialMaterial("Elastic", OFFSET + BASE_SPRING, K_FP)
    ops.uniaxialMaterial("Elastic", OFFSET + BASE_SPRING + 1, K_ROT)
    ops.element(
        "zeroLength", OFFSET + BASE_SPRING, OFFSET + FRAME + 1, OFFSET + 1,
        "-mat", OFFSET + BASE_SPRING, OFFSET + BASE_SPRING + 1, "-dir", 1, 3,
        "-doRayleigh", 1,
    )


def gravity_terms(ops):
    """The gravity (geometric) terms of the linearised rocking equations, as springs.

    Paper 001 Eqs 19-20 carry gravity as K_uθ = -g m_i and K_θθ = -g sum(m_i H_i)
    over (u, θ), where u_i is measured from the rotating base. With X_i = u_i + H_i θ,
    the potential -g m_i (u_i θ + H_i θ^2 / 2) equals, for each node,
        -(k_i / 2) X_i^2  +  (k_i / 2) (X_i - H_i θ)^2,     k_i = m_i g / H_i,
    i.e. a negative spring from node i to the ground (the P-Delta of a bar leaning on
    the base under the weight m_i g) and a positive one from node i to the base's frame
    point at its height (which removes the P-Delta of the elastic deflection u_i, a
    term the linearised equations do not have). This is exact, needs no static
    gravity step, and leaves the elastic elements linear. These springs carry no
    damping (Eq 19's C acts on u only).
    """
    for i, (h, m) in enumerate(zip(HEIGHTS, MASSES), start=1):
        k = m * G / h  # N/m
        ops.node(OFFSET + ANCHOR + i, 0.0, h)
        ops.fix(OFFSET + ANCHOR + i, 1, 1, 1)
        ops.uniaxialMaterial("Elastic", OFFSET + GRAVITY_NEG + i, -k)
        ops.uniaxialMaterial("Elastic", OFFSET + GRAVITY_POS + i, k)
        ops.element("zeroLength", OFFSET + GRAVITY_NEG + i, OFFSET + ANCHOR + i, OFFSET + i,
                    "-mat", OFFSET + GRAVITY_NEG + i, "-dir", 1)
        ops.element("zeroLength", OFFSET + GRAVITY_POS + i, OFFSET + FRAME + i, OFFSET + i,
                    "-mat", OFFSET + GRAVITY_POS + i, "-dir", 1)


def damping(ops):
    """Rayleigh damping C = a0 M + a1 K of the elastic column (multimass.model.damping).

    a0, a1 give ZETA_1 and ZETA_2 at the first two full-contact modes (OMEGA_1, OMEGA_2
    rad/s). K is the column's stiffness: the beams and the base springs, whose element
    damping is set here (not with the domain-wide `rayleigh` command, so the model can
    sit in a larger one). The mass term damps the velocity of each node relative to the
    base, u_i dot, as in paper 001 Eq 19: a dashpot a0 m_i between node i and the base's
    frame point at its height (in full contact that point is fixed: plain a0 M).
    OpenSees keeps the rotations that multimass condenses out; they carry no mass, so
    the condensed damping a1 K is reproduced exactly.
    """
    for i in range(1, len(HEIGHTS)):
        ops.setElementRayleighDampingFactors(OFFSET + i, 0.0, RAYLEIGH_A1, 0.0, 0.0)
    ops.setElementRayleighDampingFactors(OFFSET + BASE_SPRING, 0.0, RAYLEIGH_A1, 0.0, 0.0)
    for i, m in enumerate(MASSES, start=1):
        ops.uniaxialMaterial("Viscous", OFFSET + DASHPOT + i, RAYLEIGH_A0 * m, 1.0)  # N s/m
        ops.element("zeroLength", OFFSET + DASHPOT + i, OFFSET + FRAME + i, OFFSET + i,
                    "-mat", OFFSET + DASHPOT + i, "-dir", 1)


def build(ops):
    """Add the model to the current domain (2-D, 3 dof per node); returns its node tags."""
    nodes_and_masses(ops)
    elements(ops)
    base(ops)
    gravity_terms(ops)
    damping(ops)
    return [OFFSET + i for i in range(1, len(HEIGHTS) + 1)]


def start(ops):
    """Initial state: at rest, undeformed; sets up the analysis."""
    analysis(ops)


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


def report(ops):
    """Print the undamped modes: omega^2, and f = omega / 2 pi where omega^2 > 0."""
    import math

    for k, lam in enumerate(eigenvalues(ops), start=1):
        f = f"{math.sqrt(lam) / (2 * math.pi):.6g} Hz" if lam > 0 else "unstable (rocking)"
        print(f"mode {k}: omega^2 = {lam:.9g} rad^2/s^2, {f}")


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
            dst.write(f"{t} {-float(r)!r}\n")


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
