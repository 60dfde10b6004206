"""Validation of the arguments of `modal.analyse` (each helper returns the cleaned value)."""

from __future__ import annotations

import os
import reprlib
from collections.abc import Iterable, Mapping, Set

import numpy as np

from multimass.model.structure import Structure, from_specimen

from .errors import ModalError

__all__ = ["show", "validate_structure", "validate_shape_nodes"]

_REPR = reprlib.Repr()
_REPR.maxstring, _REPR.maxother, _REPR.maxlist, _REPR.maxtuple = 40, 40, 8, 8


def show(value) -> str:
    """A short one-line repr of a user's value, for error messages."""
    return " ".join(_REPR.repr(value).split())


def validate_structure(structure) -> Structure:
    """A column `Structure` from a Structure, a bundled specimen name or a TOML path.

    Raises
    ------
    ModalError
        For any other type, and for a rigid block (no elastic nodes, no vibration modes).
    """
    if isinstance(structure, (str, os.PathLike)):
        structure = from_specimen(structure)  # its own errors name the file and the key
    elif not isinstance(structure, Structure):
        raise ModalError(
            f"`structure` = {show(structure)} ({type(structure).__name__}): give a "
            "Structure (multimass.column(...)), a bundled specimen name such as "
            "'S1', or the path of a column TOML file"
        )
    if structure.n == 0:
        raise ModalError(
            f"`structure` {structure.name!r} is a rigid block: it has no elastic "
            f"nodes, so no vibration modes (it rocks with p = {structure.p:.4g} rad/s); "
            'modal analysis needs a column specimen (kind = "column")'
        )
    return structure


def validate_shape_nodes(
    shape_nodes,
    n: int,
    default: tuple[int, ...],
    arg: str = "shape_nodes",
    example: str | None = None,
) -> tuple[int, ...]:
    """Distinct 1-based integer node numbers in 1..n; `default` for None.

    A string such as ``"2,3"`` is refused, not parsed (the command line's
    ``--shape-nodes 2,3`` parses text); so are floats (2.5 is not truncated),
    bools and unordered sets.

    Parameters
    ----------
    shape_nodes : sequence of int or None
    n : int
        Number of nodes of the structure.
    default : tuple of int
        Returned for None.
    arg, example : str, optional
        The argument's name and an example value, for messages (the command
        line passes ``--shape-nodes`` and ``2,3,4``).

    Raises
    ------
    ModalError
        Naming the value and the fix.
    """
    if shape_nodes is None:
        return default
    example = example or f"{arg}={default[:3]}"
    fix = f"give distinct integer node numbers in 1..{n}, e.g. {example}"
    if isinstance(shape_nodes, (str, bytes)):
        raise ModalError(
            f"`{arg}` = {show(shape_nodes)} is a string: {fix} (a sequence of int, not text)"
        )
    if isinstance(shape_nodes, (Set, Mapping)) or not isinstance(shape_nodes, Iterable):
        raise ModalError(
            f"`{arg}` = {show(shape_nodes)} ({type(shape_nodes).__name__}) "
            f"is not an ordered sequence: {fix}"
        )
    items = list(shape_nodes)
    odd = [
        x for x in items if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer))
    ]
    if odd:
        raise ModalError(
            f"`{arg}` = {show(shape_nodes)} holds {show(odd[0])} "
            f"({type(odd[0]).__name__}), not an integer node number: {fix}"
        )
    nodes = tuple(int(x) for x in items)
    if not nodes:
        raise ModalError(f"`{arg}` is empty: {fix}")
    outside = [i for i in nodes if not 1 <= i <= n]
    if outside:
        raise ModalError(
            f"`{arg}` = {show(nodes)}: node(s) {show(outside)} outside 1..{n} "
            f"(the structure has {n} nodes): {fix}"
        )
    if len(set(nodes)) != len(nodes):
        twice = sorted({i for i in nodes if nodes.count(i) > 1})
        raise ModalError(f"`{arg}` = {show(nodes)} repeats node(s) {show(twice)}: {fix}")
    return nodes
