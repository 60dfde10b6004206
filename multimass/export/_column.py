"""The OpenSeesPy source of a column's model in full contact and uplifted (linear phases).

Each function returns the text of one section of the exported script: a function
that adds that part of the model to the current OpenSees domain, reading the
constants that `multimass.export.opensees` writes at the top of the script. Both
phases are exact renderings of the toolkit's linear systems (`multimass.modal.
linearisation`): full contact is paper 001 Eq 3, uplifted is Eqs 19–20.
"""

from __future__ import annotations

__all__ = ["NODES", "ELEMENTS", "BASE_FULL", "BASE_UPLIFTED", "GRAVITY", "DAMPING"]

NODES = '''
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
'''

ELEMENTS = '''
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
'''

BASE_FULL = '''
def base(ops):
    """Full contact: the base (node 0) and its frame points are fixed to the ground.

    Node 1 is tied to the base by K_FP (horizontal) and K_ROT (rotational) zero-length
    springs, as in paper 001 Eq 1 and Table 1's footnote.
    """
    ops.fix(OFFSET + BASE, 1, 1, 1)
    for i in range(1, len(HEIGHTS) + 1):
        ops.fix(OFFSET + FRAME + i, 1, 1, 1)
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
'''

BASE_UPLIFTED = '''
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
'''

GRAVITY = '''
def gravity_terms(ops):
    """Full contact: none. The linearised equations (paper 001, Eq 3) have no P-Delta."""
'''

DAMPING = '''
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
'''
