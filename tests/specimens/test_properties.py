"""Property-based tests of the specimen loader and the structures built from it (hypothesis).

Every outcome of loading a mapping — the bundled S1, B6M and beam with leaves replaced by
extremes, wrong types or removed, or an arbitrary mapping — and of building its structure
(and, for a few columns, its modal analysis) is either a valid object with finite values
or the package's own error (`SpecimenError`, `InputError`, `ModalError`). Any other
exception, or a non-finite number in a result, fails.

Reproducible: fixed seed (``derandomize=True``), no example database, no deadline.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import multimass
from multimass import InputError, modal, specimens
from multimass.modal.errors import ModalError
from multimass.specimens import (
    BeamSpecimen,
    BlockSpecimen,
    ColumnSpecimen,
    SpecimenError,
)

OWN_ERRORS = (SpecimenError, InputError, ModalError)
BASES = {
    name: tomllib.loads(specimens.loader._bundled()[name].read_text())
    for name in ("S1", "B6M", "beam_mudric2024")
}
SETTINGS = dict(
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


# ---------------------------------------------------------------------------- strategies
def leaf_paths(node, prefix=()):
    """Every path to a value (table keys and list indices) of a parsed TOML document."""
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    out = []
    for key, value in items:
        out.append(prefix + (key,))
        out.extend(leaf_paths(value, prefix + (key,)))
    return out


EXTREMES = [
    1e300,
    -1e300,
    1e-300,
    -1e-300,
    5e-324,
    -5e-324,
    0,
    0.0,
    -0.0,
    10**400,
    -(10**400),
    2**63,
    10**20,
    float("inf"),
    float("-inf"),
    float("nan"),
    True,
    False,
    "",
    "10",
    "abc",
    [],
    [1.0],
    [[1.0]],
    {},
    {"a": 1},
    None,
    2.5,
    -1,
    1,
]

replacement = st.one_of(
    st.sampled_from(EXTREMES),
    st.floats(width=64),  # any float, NaN and inf included
    st.integers(min_value=-(10**30), max_value=10**30),
    st.text(max_size=5),
    st.lists(st.floats(allow_nan=False), max_size=3),
)
# the slips of units and signs, applied to the value in place
scaling = st.sampled_from([1e3, 1e-3, 1e6, 1e-6, 1e9, 1e-9, 1e-8, 1e8, -1.0, 1e300, 1e-300])
# "vary" (a factor in [0.2, 5]) comes up most, so that about half the examples stay
# valid and go on to be built and checked
ACTIONS = st.sampled_from(["vary"] * 6 + ["replace", "scale", "remove", "add"])


@st.composite
def mutated(draw, base_name=None, actions=ACTIONS):
    """A bundled mapping with 1–3 leaves varied, replaced, scaled, removed or added."""
    name = base_name or draw(st.sampled_from(sorted(BASES)))
    data = copy.deepcopy(BASES[name])
    for _ in range(draw(st.integers(1, 3))):
        paths = leaf_paths(data)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        key, old = path[-1], parent[path[-1]]
        action = draw(actions)
        number = isinstance(old, (int, float)) and not isinstance(old, bool)
        if action == "vary":  # a plausible other structure
            if isinstance(old, float):
                parent[key] = old * draw(st.floats(0.2, 5.0))
        elif action == "scale" and number:
            try:
                parent[key] = old * draw(scaling)
            except OverflowError:  # an int times 1e300 is beyond float
                parent[key] = draw(replacement)
        elif action == "remove" and isinstance(parent, dict):
            del parent[key]
        elif action == "add" and isinstance(old, dict):
            old[draw(st.sampled_from(["extra", "kind", "name", "x_m"]))] = draw(replacement)
        else:
            parent[key] = draw(replacement)
    return data


scalar = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=8))
keys = st.one_of(
    st.sampled_from(
        [
            "kind",
            "name",
            "geometry",
            "mass",
            "stiffness",
            "damping",
            "restitution",
            "heights_m",
            "width_m",
            "material",
            "mesh",
        ]
    ),
    st.text(max_size=6),
    st.integers(-3, 3),
)
arbitrary = st.recursive(
    scalar,
    lambda children: st.one_of(
        st.lists(children, max_size=4), st.dictionaries(keys, children, max_size=5)
    ),
    max_leaves=12,
)
arbitrary_mapping = st.builds(
    lambda kind, rest: {**rest, "kind": kind} if kind is not None else rest,
    st.one_of(st.none(), st.sampled_from(["column", "block", "beam"]), arbitrary),
    st.dictionaries(keys, arbitrary, max_size=8),
)


# ---------------------------------------------------------------------------- checks of results
def finite(x) -> bool:
    return bool(np.all(np.isfinite(np.asarray(x, dtype=float))))


def assert_valid_specimen(spec) -> None:
    """Every number of the specimen is finite; the type follows the kind."""
    assert isinstance(spec, (ColumnSpecimen, BlockSpecimen, BeamSpecimen))
    for f in dataclasses.fields(spec):
        value = getattr(spec, f.name)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            assert math.isfinite(value), f.name
        elif isinstance(value, tuple) and value and isinstance(value[0], (int, float)):
            assert finite(value), f.name
    assert isinstance(spec.name, str) and spec.name.strip()


def assert_valid_structure(struct) -> None:
    """Finite matrices; K, M symmetric positive definite; derived quantities finite and > 0."""
    for A in (struct.K, struct.C, struct.M):
        assert finite(A) and np.array_equal(A, A.T)
    if struct.n:
        assert finite(struct.K_s)
        assert np.linalg.eigvalsh(struct.K).min() > 0
        w = struct.full_contact_omega
        assert finite(w) and w.min() > 0
    for value in struct.derived().values():
        assert math.isfinite(value) and value > 0
    assert math.isfinite(struct.p) and struct.p > 0


def load_and_build(data):
    """(specimen, structure) or the package's own error, which is returned, not raised."""
    try:
        spec = specimens.from_mapping(data, "fuzz.toml")
    except OWN_ERRORS as err:
        event("refused on loading")
        return err, None
    assert_valid_specimen(spec)
    try:
        struct = multimass.from_specimen(spec)
    except OWN_ERRORS as err:
        event(f"loaded {spec.kind}, refused on building")
        return spec, err
    assert_valid_structure(struct)
    event(f"loaded and built {spec.kind}")
    return spec, struct


# ---------------------------------------------------------------------------- properties
@settings(max_examples=400, **SETTINGS)
@given(mutated())
def test_mutated_bundled_specimens_load_build_or_say_why(data):
    spec, struct = load_and_build(data)
    if isinstance(spec, BeamSpecimen):  # a beam is a base for nscd, not a structure
        assert isinstance(struct, InputError) and "is a beam" in str(struct)


@settings(max_examples=200, **SETTINGS)
@given(arbitrary_mapping)
def test_arbitrary_mappings_load_or_say_why(data):
    load_and_build(data)


@settings(max_examples=100, **SETTINGS)
@given(st.one_of(arbitrary, st.binary(max_size=20), st.floats()))
def test_anything_not_a_mapping_is_refused(data):
    try:
        specimens.from_mapping(data)
    except SpecimenError:
        return
    assert isinstance(data, dict)


@settings(max_examples=12, **SETTINGS)
@given(mutated("S1", st.sampled_from(["vary"] * 9 + ["scale"])))
def test_varied_columns_analyse_or_say_why(data):
    spec, struct = load_and_build(data)
    if not isinstance(struct, multimass.Structure):
        return
    try:
        res = modal.analyse(struct)
    except ModalError:
        event("refused by modal.analyse")
        return
    event("analysed")
    for phase in (res.full_contact, res.rocking):
        assert finite(phase.freq_hz) and finite(phase.damping)
    assert finite(res.rocking_eigenvalues)
