"""Measured (experimental) mode shapes from CSV files, for MAC against the model.

Format: one row per measured location, one column per mode.

.. code-block:: text

    node,mode_1,mode_2
    2,0.08,0.13
    3,0.07,0.29
    4,-0.03,0.17
    5,-0.18,-0.18
    freq_hz,20.1,44.0

``node`` holds 1-based node numbers of the model; the optional last row
``freq_hz`` gives each measured mode's frequency in Hz.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import ModalError

__all__ = ["MeasuredShapes", "read_measured_shapes"]


@dataclass(frozen=True, eq=False)
class MeasuredShapes:
    """Measured shapes: `shapes` is (n_nodes, n_modes) at 1-based `nodes`."""

    nodes: tuple[int, ...]
    shapes: np.ndarray
    names: tuple[str, ...]
    freq_hz: np.ndarray | None
    source: str


def read_measured_shapes(path: str | Path) -> MeasuredShapes:
    """Read measured mode shapes from a CSV file (format in the module docstring).

    Raises
    ------
    ModalError
        If the file is missing or malformed; the message names the column or row.
    """
    p = Path(path)
    if not p.is_file():
        raise ModalError(f"measured shapes {str(p)!r}: no such file; give a CSV file of shapes")
    try:
        df = pd.read_csv(p, dtype=str, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise ModalError(f"{p}: not a readable CSV file ({exc})") from exc
    df.columns = [c.strip() for c in df.columns]
    if "node" not in df.columns:
        raise ModalError(
            f"{p}: no `node` column; the first column must be `node` "
            "(1-based node numbers), then one column per mode"
        )
    modes = [c for c in df.columns if c != "node"]
    if not modes:
        raise ModalError(f"{p}: no mode columns; add one column per measured mode")
    labels = df["node"].str.strip()
    freq_rows = labels.str.lower() == "freq_hz"
    freq = None
    if freq_rows.any():
        freq = _numbers(p, df.loc[freq_rows, modes].iloc[0], "row `freq_hz`")
        df, labels = df.loc[~freq_rows], labels[~freq_rows]
    try:
        nodes = tuple(int(x) for x in labels)
    except ValueError as exc:
        raise ModalError(
            f"{p}: column `node` holds {list(labels)}; use integer node numbers "
            "(and `freq_hz` for the optional frequency row)"
        ) from exc
    if len(set(nodes)) != len(nodes) or not nodes:
        raise ModalError(f"{p}: column `node` = {list(nodes)}: give each node once")
    shapes = np.column_stack([_numbers(p, df[c], f"column `{c}`") for c in modes])
    return MeasuredShapes(
        nodes=nodes, shapes=shapes, names=tuple(modes), freq_hz=freq, source=str(p)
    )


def _numbers(path: Path, values, where: str) -> np.ndarray:
    out = pd.to_numeric(values, errors="coerce").to_numpy(dtype=float)
    if not np.all(np.isfinite(out)):
        raise ModalError(
            f"{path}: {where} holds {list(values)}: every entry must be a finite number"
        )
    return out
