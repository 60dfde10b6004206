"""The OpenSeesPy source of the nonlinear rocking model, for columns and rigid blocks.

The structure stands on a rigid base that touches the ground at its two pivots
through compression-only contact springs (zeroLength, ENT material: elastic, no
tension), the common OpenSees practice for rocking bodies. `contact` chooses their
stiffness and damping from the specimen.
"""

from __future__ import annotations

import math

from ..model.structure import Structure

__all__ = ["contact", "sections"]

#: The contact springs' rocking frequency, as a multiple of the column's first
#: full-contact frequency ω_1 and of the frequency parameter p (rad/s): the springs then
#: lower ω_1 by about (1/30)^2 / 2 = 0.06 % and add a mode far above the rocking motion.
CONTACT_OVER_OMEGA_1 = 30.0
CONTACT_OVER_P = 200.0

#: Default damping ratio ζ_c of the contact springs, by kind (`contact`). Measured with
#: `multimass compare-opensees` (docs/opensees): a rigid block (B6M) released from 0.1 rad
#: follows Housner's decay (r = 1 - 1.5 sin^2 alpha) within 4 % over six impacts at
#: ζ_c = 0.01 (at ζ_c = 1 it is at rest after three impacts); a column (S1) released
#: from 0.11 rad at ζ_c = 0.1 has its peaks within 0.005 rad of the toolkit's DD2 run.
CONTACT_DAMPING = {"block": 0.01, "column": 0.1}

#: How much stiffer the rigid parts (the base's arms, node 1's vertical tie) are than
#: the contact springs they carry: stiff, and not so stiff that Newton's iterations
#: stall on round-off.
RIGID = 1e2


def contact(s: Structure) -> dict:
    """Contact stiffness and frequency chosen from the structure.

    Returns ``{"omega_c", "k_n", "zeta_c"}``: ω_c = max(30 ω_1, 200 p) (rad/s) is the frequency
    of the structure rotating on the two springs as a rigid body, so each spring has
    k_n = J_p ω_c² / (2 B²) (N/m), its rotational stiffness 2 k_n B² being J_p ω_c²;
    ζ_c is the default damping ratio of its kind (`CONTACT_DAMPING`).
    """
    omega_1 = float(s.full_contact_omega[0]) if not s.is_rigid else 0.0
    omega_c = max(CONTACT_OVER_OMEGA_1 * omega_1, CONTACT_OVER_P * s.p)
    zeta_c = CONTACT_DAMPING["block" if s.is_rigid else "column"]
    return {"omega_c": omega_c, "k_n": s.J_p * omega_c**2 / (2.0 * s.B**2), "zeta_c": zeta_c}


def _constants(s: Structure, release, contact_damping: float) -> str:
    c = contact(s)
    hub_y = float(s.H[0]) if not s.is_rigid else float(s.h0)
    arm = math.hypot(s.B, hub_y)
    lines = [
        "",
        "# ---------------------------------------------------------------- rocking contact",
        "# Contact springs at the pivots: compression-only (ENT). Their stiffness makes the",
        "# structure, rotating rigidly on them, vibrate at OMEGA_C = max(30 omega_1, 200 p):",
        "# far above the rocking and the column's first modes, which it lowers by ~0.06 %.",
        f"OMEGA_C = {c['omega_c']!r}  # rad/s",
        f"K_N = {c['k_n']!r}  # N/m, each spring: 2 K_N B^2 = J_p OMEGA_C^2",
        "# Their damping, stiffness-proportional on the committed tangent (so it acts only",
        "# while a spring is in contact), gives the contact mode ZETA_C of critical. An",
        "# impact on stiff springs loses energy by itself (it excites the bouncing of the",
        "# base, which the damping then removes); ZETA_C sets how much. Defaults, measured",
        "# against the toolkit (docs/opensees): 0.01 for a rigid block (Housner's decay",
        "# within 4 % over six impacts), 0.1 for a column (S1: peaks within 0.005 rad of",
        "# the toolkit's DD2).",
        f"ZETA_C = {contact_damping!r}",
        "BETA_C = 2.0 * ZETA_C / OMEGA_C  # s",
        "# Sliding is prevented at the base's centre (X fixed at the foot, level with the",
        "# pivots): exact at impact (theta = 0); while rocking the corners move by",
        "# B (1 - cos theta) ~ B theta^2 / 2, the kinematics' second-order difference.",
        f"HUB_Y = {hub_y!r}  # m, the base's reference node (node 1's level for a column)",
        f"RIGID_EA = {RIGID * c['k_n'] * arm!r}  # N, the base's arms: EA / L = 100 K_N",
        f"RIGID_EI = {RIGID * c['k_n'] * arm**3 / 3.0!r}  # N m^2, 3 EI / L^3 = 100 K_N",
        f"K_AXIAL = {RIGID * c['k_n']!r}  # N/m, node 1 on the base, vertically",
        f"RELEASE = {release!r}  # rad, initial theta (None: start at rest, upright)",
        "CORNER_R, CORNER_L, GROUND_R, GROUND_L, FOOT, MASS_NODE = 1002, 1003, 1004, 1005, 1006, 1007",
        "ARM, CONTACT = 1100, 1200",
        "",
    ]
    return "\n".join(lines)


NODES = '''
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
'''

ELEMENTS = '''
def elements(ops):
    """Elastic beam-columns E_s I_s between the nodes, corotational (large rotations).

    The axial stiffness E_S AXIAL_AREA / L is 1e3 x the bending stiffness 12 E_S I_S / L^3
    of the shortest element: the column is inextensible as in multimass's model.
    """
    ops.geomTransf("Corotational", OFFSET + 1)
    for i in range(1, len(HEIGHTS)):
        ops.element(
            "elasticBeamColumn", OFFSET + i, OFFSET + i, OFFSET + i + 1,
            AXIAL_AREA, E_S, I_S, OFFSET + 1,
        )
'''

BASE = '''
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
'''

BASE_SPRINGS_COLUMN = '''
def base_springs(ops):
    """Node 1 on the base: K_FP in X, K_AXIAL (stiff) in Y, K_ROT on the rotation.

    Frame points at the heights of nodes 2..N, carried by stiff arms from the hub, are
    the references of the relative velocities that the mass-proportional damping acts on.
    """
    ops.uniaxialMaterial("Elastic", OFFSET + BASE_SPRING, K_FP)
    ops.uniaxialMaterial("Elastic", OFFSET + BASE_SPRING + 1, K_AXIAL)
    ops.uniaxialMaterial("Elastic", OFFSET + BASE_SPRING + 2, K_ROT)
    ops.element(
        "zeroLength", OFFSET + BASE_SPRING, OFFSET + BASE, OFFSET + 1,
        "-mat", *(OFFSET + BASE_SPRING + k for k in range(3)), "-dir", 1, 2, 3,
        "-doRayleigh", 1,
    )
    for i, h in enumerate(HEIGHTS[1:], start=2):
        ops.node(OFFSET + FRAME + i, 0.0, h)
        ops.element("elasticBeamColumn", OFFSET + FRAME + i, OFFSET + BASE, OFFSET + FRAME + i,
                    AXIAL_AREA, E_S, 1e3 * I_S, OFFSET + 1)


def _frame(i):
    return OFFSET + (BASE if i == 1 else FRAME + i)
'''

BASE_SPRINGS_BLOCK = '''
def base_springs(ops):
    """A rigid block has no elastic column: nothing ties it to the base but rigidity."""
'''

DAMPING_COLUMN = '''
def damping(ops):
    """Rayleigh damping of the column (multimass.model.damping), as in the linear phases.

    a1 K on the beams and the base springs; a0 m_i as a dashpot between node i and the
    base's frame point at its height, so the mass term damps u_i dot, the velocity
    relative to the rocking base (paper 001, Eq 4), not the rocking itself.
    """
    for i in range(1, len(HEIGHTS)):
        ops.setElementRayleighDampingFactors(OFFSET + i, 0.0, RAYLEIGH_A1, 0.0, 0.0)
    ops.setElementRayleighDampingFactors(OFFSET + BASE_SPRING, 0.0, RAYLEIGH_A1, 0.0, 0.0)
    for i, m in enumerate(MASSES, start=1):
        ops.uniaxialMaterial("Viscous", OFFSET + DASHPOT + i, RAYLEIGH_A0 * m, 1.0)  # N s/m
        ops.element("zeroLength", OFFSET + DASHPOT + i, _frame(i), OFFSET + i,
                    "-mat", OFFSET + DASHPOT + i, "-dir", 1)
'''

DAMPING_BLOCK = '''
def damping(ops):
    """A rigid block: no structural damping; energy is lost at the contacts only."""
'''

START = '''
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
'''

ANALYSIS = '''
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
'''


def sections(s: Structure, release, contact_damping: float) -> list[str]:
    """The script's sections for the rocking phase of `s`."""
    parts = [_constants(s, release, contact_damping), NODES]
    if s.is_rigid:
        parts += ['\ndef elements(ops):\n    """A rigid block has no elastic elements."""\n']
        parts += [BASE, BASE_SPRINGS_BLOCK, DAMPING_BLOCK]
    else:
        parts += [ELEMENTS, BASE, BASE_SPRINGS_COLUMN, DAMPING_COLUMN]
    return parts + [START, ANALYSIS]
