"""OpenSeesPy model of specimen B6M, phase rocking.

Phase: nonlinear: a rigid base on two compression-only contact springs at the pivots.

Specimen: B6M. Medium slender block, h/b = 4.5 (the same block in papers 002 and 004).
Source: paper 004, Table 1; paper 002, Table 1.
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
NAME = 'B6M'
PHASE = 'rocking'
OFFSET = 0  # added to every tag below
G = 9.81  # m/s^2
B = 0.0225  # m, half the distance between the pivots
HEIGHTS = []  # m, nodes 1..N above the base
MASSES = []  # kg, lumped at nodes 1..N
M0 = 1.0896  # kg, the block
J0 = 0.0039072375  # kg m^2, the block's rotary inertia about its centre of mass
H0 = 0.10125  # m, height of the base's centre of mass above the pivots

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
DT = 0.00016666666666666666  # s, analysis step (multimass.export.default_dt)
OUTPUT_DT = 0.001  # s, recorders' step
N_MODES = 0  # modes with mass


# ---------------------------------------------------------------- rocking contact
# Contact springs at the pivots: compression-only (ENT). Their stiffness makes the
# structure, rotating rigidly on them, vibrate at OMEGA_C = max(30 omega_1, 200 p):
# far above the rocking and the column's first modes, which it lowers by ~0.06 %.
OMEGA_C = 1684.473326671581  # rad/s
K_N = 43798884.1933052  # N/m, each spring: 2 K_N B^2 = J_p OMEGA_C^2
# Their damping, stiffness-proportional on the committed tangent (so it acts only
# while a spring is in contact), gives the contact mode ZETA_C of critical. An
# impact on stiff springs loses energy by itself (it excites the bouncing of the
# base, which the damping then removes); ZETA_C sets how much. Defaults, measured
# against the toolkit (docs/opensees): 0.01 for a rigid block (Housner's decay
# within 4 % over six impacts), 0.1 for a column (S1: peaks within 0.005 rad of
# the toolkit's DD2).
ZETA_C = 0.01
BETA_C = 2.0 * ZETA_C / OMEGA_C  # s
# Sliding is prevented at the base's centre (X fixed at the foot, level with the
# pivots): exact at impact (theta = 0); while rocking the corners move by
# B (1 - cos theta) ~ B theta^2 / 2, the kinematics' second-order difference.
HUB_Y = 0.10125  # m, the base's reference node (node 1's level for a column)
RIGID_EA = 454281480.0000001  # N, the base's arms: EA / L = 100 K_N
RIGID_EI = 1629024.9946875006  # N m^2, 3 EI / L^3 = 100 K_N
K_AXIAL = 4379888419.330521  # N/m, node 1 on the base, vertically
RELEASE = 0.1  # rad, initial theta (None: start at rest, upright)
CORNER_R, CORNER_L, GROUND_R, GROUND_L, FOOT, MASS_NODE = 1002, 1003, 1004, 1005, 1006, 1007
ARM, CONTACT = 1100, 1200


def nodes_and_masses(ops):
    """Nodes 1..N with their masses (free in X, Y and rotation); the rigid base's nodes.

    The base is one rigid body: its hub (BASE, at HUB_Y, where node 1's springs attach),
    the corners at (+-B, 0) on the contact springs, the foot (0, 0), and the centre of
    mass (0, H0) carrying M0 and J0 (the hub itself when it is there).
    """
    for i, (h, m) in enumerate(zip(HEIGHTS, MASSES), start=1):
        ops.node(OFFSET + i, 0.0, h)
        ops.mass(OFFSET + i, m, m, 0.0)  # kg
    ops.node(OFFSET + BASE, 0.0, HUB_Y)
    ops.node(OFFSET + CORNER_R, B, 0.0)
    ops.node(OFFSET + CORNER_L, -B, 0.0)
    for tag, x in ((GROUND_R, B), (GROUND_L, -B)):
        ops.node(OFFSET + tag, x, 0.0)
        ops.fix(OFFSET + tag, 1, 1, 1)
    if HUB_Y != 0.0:
        ops.node(OFFSET + FOOT, 0.0, 0.0)
    ops.fix(_foot(), 1, 0, 0)  # no sliding (see the note at RELEASE)
    if H0 != HUB_Y:
        ops.node(OFFSET + MASS_NODE, 0.0, H0)
    ops.mass(_mass_node(), M0, M0, J0)  # kg, kg, kg m^2


def _foot():
    return OFFSET + (FOOT if HUB_Y != 0.0 else BASE)


def _mass_node():
    return OFFSET + (MASS_NODE if H0 != HUB_Y else BASE)


def elements(ops):
    """A rigid block has no elastic elements."""


def base(ops):
    """The rigid base: stiff corotational arms from the hub to the corners, foot, mass."""
    ops.geomTransf("Corotational", OFFSET + 2)
    ends = [CORNER_R, CORNER_L] + ([FOOT] if HUB_Y != 0.0 else [])
    ends += [MASS_NODE] if H0 != HUB_Y else []
    for k, end in enumerate(ends):
        ops.element("elasticBeamColumn", OFFSET + ARM + k, OFFSET + BASE, OFFSET + end,
                    1.0, RIGID_EA, RIGID_EI, OFFSET + 2)
    base_springs(ops)
    contact_springs(ops)


def contact_springs(ops):
    """Compression-only springs K_N at the pivots, damped only in contact (BETA_C)."""
    ops.uniaxialMaterial("ENT", OFFSET + CONTACT, K_N)
    for k, (ground, corner) in enumerate(((GROUND_R, CORNER_R), (GROUND_L, CORNER_L))):
        tag = OFFSET + CONTACT + k
        ops.element("zeroLength", tag, OFFSET + ground, OFFSET + corner,
                    "-mat", OFFSET + CONTACT, "-dir", 2, "-doRayleigh", 1)
        ops.setElementRayleighDampingFactors(tag, 0.0, 0.0, 0.0, BETA_C)


def base_springs(ops):
    """A rigid block has no elastic column: nothing ties it to the base but rigidity."""


def damping(ops):
    """A rigid block: no structural damping; energy is lost at the contacts only."""


def build(ops):
    """Add the model to the current domain (2-D, 3 dof per node); returns its node tags."""
    nodes_and_masses(ops)
    elements(ops)
    base(ops)
    damping(ops)
    return [OFFSET + i for i in range(1, len(HEIGHTS) + 1)] + [_mass_node()]


def gravity(ops):
    """Apply the weights (N) in 10 static steps, then hold them constant (time 0)."""
    ops.timeSeries("Linear", OFFSET + GRAVITY_SERIES)
    ops.pattern("Plain", OFFSET + GRAVITY_SERIES, OFFSET + GRAVITY_SERIES)
    for i, m in enumerate(MASSES, start=1):
        ops.load(OFFSET + i, 0.0, -m * G, 0.0)
    ops.load(_mass_node(), 0.0, -M0 * G, 0.0)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    if ops.analyze(10) != 0:
        raise RuntimeError("the gravity step did not converge")
    ops.loadConst("-time", 0.0)
    ops.wipeAnalysis()


def _all_nodes():
    nodes = [OFFSET + i for i in range(1, len(HEIGHTS) + 1)]
    nodes += [OFFSET + FRAME + i for i in range(2, len(HEIGHTS) + 1)]
    nodes += [OFFSET + t for t in (BASE, CORNER_R, CORNER_L)]
    nodes += [OFFSET + FOOT] if HUB_Y != 0.0 else []
    return nodes + ([OFFSET + MASS_NODE] if H0 != HUB_Y else [])


def tilt(ops, theta):
    """Rotate the whole structure rigidly by theta (rad) about the pivot it leans on."""
    import math

    px = B if theta > 0 else -B
    c, s = math.cos(theta), math.sin(theta)
    shift = px - c * px  # the foot's X stays fixed: the pivot slides by B (1 - cos theta)
    for node in _all_nodes():
        x0, y0 = ops.nodeCoord(node)
        ux, uy, r = ops.nodeDisp(node)
        x, y = x0 + ux - px, y0 + uy
        # clockwise by theta about (px, 0): theta > 0 leans towards +X
        ops.setNodeDisp(node, 1, px + c * x + s * y - x0 - shift, "-commit")
        ops.setNodeDisp(node, 2, -s * x + c * y - y0, "-commit")
        ops.setNodeDisp(node, 3, r - theta, "-commit")


def start(ops):
    """Gravity, then the release (if any): the structure starts at rest."""
    gravity(ops)
    if RELEASE:
        tilt(ops, RELEASE)
    analysis(ops)


def analysis(ops):
    """A nonlinear transient analysis: Newton on Newmark's average acceleration.

    No numerical damping (gamma = 1/2, beta = 1/4): energy leaves only through the
    structure's and the contacts' damping. DT resolves the contact springs' period
    2 pi / OMEGA_C with 20 steps.
    """
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def run(ops, folder=".", t_end=None, dt=None):
    """Integrate to `t_end` (s) in steps `dt` (s), a failed step retried in tenths."""
    t_end = T_END if t_end is None else t_end
    dt = DT if dt is None else dt
    for _ in range(int(round(t_end / dt))):
        if ops.analyze(1, dt) != 0:
            ops.algorithm("KrylovNewton")
            status = ops.analyze(10, dt / 10)
            ops.algorithm("Newton")
            if status != 0:
                return status
    return 0


def report(ops):
    """Print what the contact model is."""
    print(f"{NAME}: contact springs K_N = {K_N:.4g} N/m, OMEGA_C = {OMEGA_C:.4g} rad/s, "
          f"ZETA_C = {ZETA_C}")


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
