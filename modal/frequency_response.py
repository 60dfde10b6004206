"""State-space models of the linearised phases and their frequency responses (python-control).

The linearised system of a phase (`multimass.modal.linearisation`: paper 001's
Eq 3 in full contact, Eqs 19–20 rocking), M z̈ + C ż + K z = −r ü_g, is written
as a first-order model with state x = [z; ż] (A of `multimass.modal.eigen.state_matrix`), input the
ground acceleration ü_g and outputs what a shake-table test records:

* the total horizontal acceleration of each sensor node, linearised from paper
  001's Eq 7 about θ = 0: a_i = ü_i + H_i θ̈ + ü_g − g θ (the last term is the
  tilt of the sensor, which reads gravity while the structure rocks); in full
  contact a_i = ü_i + ü_g;
* θ, while rocking.

The constant load ±m_t g B of the rocking phase (`LinearSystem.f0`) shifts the
static state only; it has no part in a frequency response.

The poles of the model are the Foss eigenvalues of `multimass.modal.eigen`
(tests/modal/test_frequency_response.py checks them to 1e-10).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from multimass.model.structure import Structure

from .eigen import check_system, state_matrix
from .errors import ModalError
from .linearisation import full_contact, rocking

__all__ = ["state_space", "frf", "sensor_nodes", "sensor_label", "PHASES"]

#: The phases a state-space model can be built for.
PHASES = ("full_contact", "rocking")


def _sensors(structure: Structure, sensors) -> np.ndarray:
    n = structure.n
    if sensors is None:
        return np.arange(n)
    idx = np.asarray(sensors)
    if idx.ndim != 1 or idx.dtype.kind not in "iu" or idx.size == 0:
        raise ModalError(
            f"`sensors` = {sensors!r}: give a list of node numbers 1..{n}, e.g. [1, {n}]"
        )
    if idx.min() < 1 or idx.max() > n:
        raise ModalError(f"`sensors` = {list(idx)!r}: node numbers run from 1 to {n}")
    return idx - 1


def sensor_nodes(structure: Structure, sensors=None) -> tuple[int, ...]:
    """1-based nodes of `sensors`: node numbers or the specimen's sensor names (e.g. "A4").

    Parameters
    ----------
    structure : Structure
    sensors : sequence of int or str, optional
        Node numbers (1..N) or names of the specimen's ``[sensors]`` table, mixed
        freely. Default: the nodes of the specimen's named sensors, else every node.

    Returns
    -------
    tuple of int
        Distinct nodes, in the order given.

    Raises
    ------
    ModalError
        For an unknown sensor name, a node outside 1..N or a repeated node.
    """
    spec = getattr(structure, "specimen", None)
    named = tuple(getattr(spec, "sensors", ()) or ())
    if sensors is None:
        nodes = sorted({node for _, node in named}) or range(1, structure.n + 1)
        return tuple(int(k) for k in nodes)
    if isinstance(sensors, (str, int, np.integer)):
        sensors = [sensors]
    out = []
    for item in sensors:
        if isinstance(item, str) and not item.strip().isdigit():
            hit = [node for key, node in named if key.lower() == item.strip().lower()]
            if not hit:
                known = ", ".join(k for k, _ in named) or "none (the specimen has no [sensors])"
                raise ModalError(
                    f"`sensors`: {structure.name!r} has no sensor {item!r}; known sensors: "
                    f"{known}; or give node numbers 1..{structure.n}"
                )
            out.append(int(hit[0]))
        elif isinstance(item, bool) or not isinstance(item, (str, int, np.integer)):
            raise ModalError(
                f"`sensors` holds {item!r}: give node numbers 1..{structure.n} or sensor names"
            )
        else:
            out.append(int(item))
    bad = [k for k in out if not 1 <= k <= structure.n]
    if bad:
        raise ModalError(f"`sensors`: node(s) {bad} outside 1..{structure.n}")
    if len(set(out)) != len(out):
        raise ModalError(f"`sensors` = {out}: give each node once")
    return tuple(out)


def sensor_label(structure: Structure, node: int) -> str:
    """``"A4 (node 5)"`` for a named sensor, else ``"node 5"``."""
    spec = getattr(structure, "specimen", None)
    names = [k for k, n in (getattr(spec, "sensors", ()) or ()) if n == node]
    return f"{'/'.join(names)} (node {node})" if names else f"node {node}"


def _matrices(structure: Structure, phase: str, sensors):
    """(A, B, C, D, output names) of `phase` with sensor nodes `sensors` (1-based)."""
    if phase not in PHASES:
        raise ModalError(f"`phase` = {phase!r}: use 'full_contact' or 'rocking'")
    system = full_contact(structure) if phase == "full_contact" else rocking(structure)
    check_system(system)
    idx = _sensors(structure, sensors)
    n, N = system.n, structure.n
    A = state_matrix(system)
    B = np.zeros((2 * n, 1))
    B[n:, 0] = -sla.solve(system.M, system.r, assume_a="pos")  # z̈ = … − M⁻¹ r ü_g
    # z̈ = A[n:] x + B[n:] ü_g, so any output linear in z̈, z and ü_g is a row of C, D
    zdd_x, zdd_u = A[n:, :], B[n:, 0]
    rows, feed, names = [], [], []
    for i in idx:  # a_i = ü_i (+ H_i θ̈ − g θ while rocking) + ü_g
        c = zdd_x[i].copy()
        d = zdd_u[i] + 1.0
        if phase == "rocking":
            c += structure.H[i] * zdd_x[N]
            c[N] -= structure.g
            d += structure.H[i] * zdd_u[N]
        rows.append(c)
        feed.append(d)
        names.append(f"a{i + 1}")
    if phase == "rocking":
        c = np.zeros(2 * n)
        c[N] = 1.0
        rows.append(c)
        feed.append(0.0)
        names.append("theta")
    return A, B, np.array(rows), np.array(feed)[:, None], names


def state_space(structure: Structure, phase: str = "full_contact", sensors=None):
    """The linearised `phase` as a python-control state-space model from ü_g to the sensors.

    Parameters
    ----------
    structure : Structure
        A column with elastic nodes (`multimass.column`).
    phase : {"full_contact", "rocking"}
        Full contact (paper 001, Eq 3) or rocking linearised about θ = 0 (Eqs 19–20).
    sensors : sequence of int, optional
        Node numbers (1..N) whose total accelerations are outputs; default all.

    Returns
    -------
    control.StateSpace
        Input ``ag`` (m/s²); outputs ``a<i>`` (m/s², total accelerations) and,
        rocking, ``theta`` (rad); states ``u<i>``, (``theta``), then their rates.
        Its poles are the Foss eigenvalues of the phase.

    Raises
    ------
    ModalError
        For a phase not in `PHASES`, a rigid body (no elastic nodes) or a bad sensor list.
    """
    import control  # python-control takes 1–3 s to import; only this function needs it

    if not isinstance(structure, Structure):
        raise ModalError(
            f"`structure` is a {type(structure).__name__}: give a multimass Structure, "
            "e.g. multimass.column('S1')"
        )
    A, B, C, D, outputs = _matrices(structure, phase, sensors)
    dofs = [f"u{i + 1}" for i in range(structure.n)] + (["theta"] if phase == "rocking" else [])
    states = dofs + [f"{d}dot" for d in dofs]
    return control.ss(A, B, C, D, inputs=["ag"], outputs=outputs, states=states)


def frf(structure: Structure, freq_hz, phase: str = "full_contact", sensors=None) -> np.ndarray:
    """Frequency response H(f) from ü_g to the outputs of `state_space`.

    Evaluated directly as C (j2πf I − A)⁻¹ B + D (one linear solve per frequency),
    without python-control.

    Parameters
    ----------
    structure, phase, sensors :
        As in `state_space`.
    freq_hz : array_like
        Frequencies (Hz), ≥ 0.

    Returns
    -------
    ndarray, complex, shape (outputs, frequencies)
    """
    f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ModalError(f"`freq_hz`: give finite frequencies ≥ 0 (Hz), got {freq_hz!r}")
    A, B, C, D, _ = _matrices(structure, phase, sensors)
    eye = np.eye(A.shape[0])
    out = np.empty((C.shape[0], f.size), dtype=complex)
    for k, fk in enumerate(f):
        out[:, k] = C @ np.linalg.solve(2j * np.pi * fk * eye - A, B[:, 0]) + D[:, 0]
    return out
