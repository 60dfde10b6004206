"""Large overturning maps streamed to disk in Parquet chunks, resumable.

A map of a million cells does not fit in memory as Python objects (one row dict per
cell is ~1 kB). `run_stored` cuts the grid (row-major: amplitude rows, ω/p within a
row) into chunks of `STORE_CHUNK_CELLS` cells; each chunk is simulated on the
executor (`simulate_cells`, so the compiled batches and the engine's scheduling are
the same as in memory) and written at once to ``DIR/cells/chunk-NNNNN.parquet``
(pyarrow; written to a hidden temporary file, then renamed, so a killed run leaves
no half chunk). ``DIR/manifest.json`` records the block, the grid, the model options
and their hash; a re-run with the same arguments skips the chunks on disk and
computes only the missing ones, and a re-run with other arguments into the same
folder is refused (`MapStoreMismatch`). The refined boundary cells go to
``DIR/cells/refined.parquet``; ``pd.read_parquet(DIR / "cells")`` gives the same
table as `OverturningMap.cells` of the in-memory map.

`StoredMap` builds the outcome grid, the summary and the figure from the stored
columns as numpy arrays (one int8 code per cell), never one Python object per cell.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from .engine import _Bar
from .map_cells import CellResults

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "StoredMap",
    "MapStoreMismatch",
    "run_stored",
    "grid_segments",
    "STORE_CHUNK_CELLS",
    "STORE_MIN_CELLS",
    "MANIFEST",
    "WALL_TIME_COVERS",
]

#: Cells per stored chunk (~1 s of work on 2 workers at 0.11 ms per cell; an interrupted
#: run loses at most the chunk in flight).
STORE_CHUNK_CELLS = 20_000
#: Grids with more cells than this stream to disk in the CLI (`multimass stability`).
STORE_MIN_CELLS = 250_000
MANIFEST = "manifest.json"
_FORMAT = 1
_OUTCOMES = ("no_rocking", "rest", "overturned", "undecided")  # codes = positions
#: What a map's ``wall_time_s`` covers (said in its summary; `multimass.sweeps.maps`).
WALL_TIME_COVERS = (
    "the overturning_map call, start to finish: validating the arguments, loading the "
    "compiled kernels, the cells, the boundary refinement and assembling the tables"
)


class MapStoreMismatch(InputError):
    """The folder holds (part of) a map computed with other arguments."""


def _manifest(st, pulse, omega_p, amp, options, chunk_cells) -> dict:
    body = {
        "format": _FORMAT,
        "block": st.name,
        "specimen": hashlib.sha256(repr(st.specimen).encode()).hexdigest(),
        "pulse": pulse,
        "omega_p": [float(w) for w in omega_p],
        "amp": [float(a) for a in amp],
        "options": json.loads(json.dumps(options, sort_keys=True, default=repr)),
        "chunk_cells": int(chunk_cells),
    }
    digest = hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()
    return body | {"hash": digest}


def _open(folder: Path, manifest: dict) -> None:
    """Create the store, or check that the one in `folder` holds the same map."""
    path = folder / MANIFEST
    (folder / "cells").mkdir(parents=True, exist_ok=True)
    if path.exists():
        old = json.loads(path.read_text())
        if old.get("hash") != manifest["hash"]:
            differ = sorted(k for k in manifest if k != "hash" and old.get(k) != manifest[k])
            raise MapStoreMismatch(
                f"`--out` = {str(folder)!r} holds a map computed with other arguments "
                f"(they differ in: {', '.join(differ) or 'format'}); re-run with the "
                "arguments recorded in its manifest.json to resume it, or choose a new "
                "--out folder (or delete this one) to start a new map"
            )
        return
    tmp = folder / f".{MANIFEST}.tmp"
    tmp.write_text(json.dumps(manifest, indent=1))
    os.replace(tmp, path)


def _chunk_path(folder: Path, c: int) -> Path:
    return folder / "cells" / f"chunk-{c:05d}.parquet"


def _table(w, a, results, grid: bool):
    import pyarrow as pa

    if not isinstance(results, CellResults):
        results = CellResults.of_rows(results)
    w, a = np.asarray(w, float), np.asarray(a, float)
    return pa.table(
        {
            "omega_p": pa.array(w, pa.float64()),
            "amp": pa.array(a, pa.float64()),
            "outcome": pa.array(results.names(), pa.string()).dictionary_encode(),
            "overturn_time": pa.array(results.overturn_time, pa.float64()),
            "theta_max_over_alpha": pa.array(results.theta_max_over_alpha, pa.float64()),
            "n_impacts": pa.array(results.n_impacts, pa.int64()),
            "accurate": pa.array(results.accurate, pa.bool_()),
            "grid": pa.array(np.full(len(w), grid), pa.bool_()),
        }
    )


def _write_chunk(path: Path, table) -> None:
    """Write atomically: a hidden temporary file (pyarrow datasets skip it), then rename."""
    import pyarrow.parquet as pq

    tmp = path.with_name(f".{path.name}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def _corrupted(path: Path, folder: Path, exc: Exception) -> InputError:
    """The one-line error for a stored file pyarrow cannot read."""
    what = "a chunk of cells" if path.name.startswith("chunk-") else "a file of the map"
    return InputError(
        f"{path}: {what} is corrupted (pyarrow: {exc}); delete that file and run the same "
        f"command again to recompute it, or delete the folder {folder} to start afresh"
    )


def _check_readable(path: Path, folder: Path) -> None:
    """Raise `_corrupted` if `path`'s Parquet footer cannot be read (a cheap check)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        pq.read_metadata(path)
    except (pa.ArrowException, OSError) as exc:
        raise _corrupted(path, folder, exc) from None


def run_stored(
    folder,
    st,
    pulse,
    omega_p,
    amp,
    options,
    simulate,
    *,
    refine,
    bisect,
    progress,
    chunk_cells,
    started=None,
    simulated=(0.0,),
):
    """Compute the missing chunks of a stored map, then its refinement; return a `StoredMap`.

    ``simulate(pairs, desc)`` returns the `map_cell` results (`CellResults`) of (ω/p,
    a0/(α g)) pairs;
    ``bisect(segments, rounds, simulate)`` is `maps._bisect`. The map's ``wall_time_s``
    counts from `started` (a `time.perf_counter` reading; default: this call) to the
    map read back from disk; ``simulated[0]`` holds the seconds `simulate` spent, read
    at the end.
    """
    folder = Path(folder)
    manifest = _manifest(st, pulse, omega_p, amp, options | {"refine": refine}, chunk_cells)
    _open(folder, manifest)
    n_w, n = len(omega_p), len(omega_p) * len(amp)
    n_chunks = -(-n // chunk_cells)
    todo = [c for c in range(n_chunks) if not _chunk_path(folder, c).exists()]
    for f in sorted((folder / "cells").glob("*.parquet")):  # before any new work
        _check_readable(f, folder)
    wall = time.perf_counter() if started is None else started
    show = progress if progress is not None else bool(getattr(sys.stderr, "isatty", bool)())
    done_cells = n - sum(min(chunk_cells, n - c * chunk_cells) for c in todo)
    bar = _Bar(
        total=n,
        initial=done_cells,
        desc=f"{st.name} {pulse} map",
        unit="cell",
        file=sys.stderr,
        disable=not show,
    )
    try:
        for c in todo:
            i = np.arange(c * chunk_cells, min((c + 1) * chunk_cells, n))
            w, a = omega_p[i % n_w], amp[i // n_w]
            results = simulate(np.column_stack([w, a]), None)
            _write_chunk(_chunk_path(folder, c), _table(w, a, results, True))
            bar.update(len(i))
    finally:
        bar.close()
    m = StoredMap.read(folder)
    finished = folder / "boundaries.parquet"  # written last: the refinement is complete
    if not finished.exists():
        segments = grid_segments(m.codes, omega_p, amp)
        extra, done = bisect(segments, refine, simulate)
        if extra:
            w, a, results = zip(*extra)
            _write_chunk(folder / "cells" / "refined.parquet", _table(w, a, results, False))
        import pandas as pd  # here: a map held in memory needs no pandas at import

        tmp = folder / f".{finished.name}.tmp"
        pd.DataFrame(done, columns=_SEGMENT_COLUMNS).to_parquet(tmp)
        os.replace(tmp, finished)
    m = StoredMap.read(folder)
    return m.with_run(len(todo), n_chunks - len(todo), time.perf_counter() - wall, simulated[0])


_SEGMENT_COLUMNS = ["omega_p", "amp_low", "amp_high", "low_outcome", "high_outcome"]


def grid_segments(codes: np.ndarray, omega_p, amp) -> list:
    """Boundary brackets of a grid of outcome codes (amp × ω/p), as `maps._refine` finds them:
    neighbouring amplitudes at one ω/p that differ in overturning, neither undecided."""
    over, und = _OUTCOMES.index("overturned"), _OUTCOMES.index("undecided")
    lo, hi = codes[:-1], codes[1:]
    flip = ((lo == over) != (hi == over)) & (lo != und) & (hi != und)
    ia, iw = np.nonzero(flip)
    order = np.lexsort((ia, iw))
    return [
        [
            float(omega_p[iw[k]]),
            float(amp[ia[k]]),
            float(amp[ia[k] + 1]),
            _OUTCOMES[lo[ia[k], iw[k]]],
            _OUTCOMES[hi[ia[k], iw[k]]],
        ]
        for k in order
    ]


def _read_columns(files, columns) -> dict:
    import pyarrow as pa
    import pyarrow.parquet as pq

    parts = {c: [] for c in columns}
    for f in files:
        try:
            t = pq.read_table(f, columns=columns)
        except (pa.ArrowException, OSError) as exc:
            raise _corrupted(Path(f), Path(f).parent.parent, exc) from None
        for c in columns:
            col = t.column(c)
            if c == "outcome":  # dictionary-encoded names → codes (positions in _OUTCOMES)
                codes = [_codes(ch) for ch in col.chunks]
                parts[c].append(np.concatenate(codes) if codes else np.zeros(0, np.int8))
            else:
                parts[c].append(col.to_numpy())
    return {c: np.concatenate(v) if v else np.zeros(0) for c, v in parts.items()}


def _codes(chunk) -> np.ndarray:
    import pyarrow as pa

    if not pa.types.is_dictionary(chunk.type):
        chunk = chunk.dictionary_encode()
    lookup = np.array([_OUTCOMES.index(s) for s in chunk.dictionary.to_pylist()], np.int8)
    return lookup[chunk.indices.to_numpy(zero_copy_only=False)]


@dataclass(frozen=True, eq=False)
class StoredMap:
    """An overturning map stored in a folder (see the module docstring).

    Attributes
    ----------
    folder : Path
    block, pulse : str
    omega_p, amp : ndarray
    codes : ndarray of int8, shape (len(amp), len(omega_p))
        Outcome code per base-grid cell (position in `OUTCOMES`), -1 if not computed yet.
    boundaries : pandas.DataFrame
    options : dict
    extra : dict
        Columns (ω/p, amp, code, accurate) of the refined boundary cells.
    inaccurate : int
    bad_cells : ndarray
        Flat indices of the grid cells whose accuracy check failed.
    chunks_computed, chunks_skipped : int
        Chunks computed by this run, and found on disk from an earlier one.
    wall_time_s : float
        Seconds of the `overturning_map` call that computed or resumed it, start to
        finish (reading the stored chunks back included).
    simulation_time_s : float
        The part of `wall_time_s` spent simulating cells.
    """

    folder: Path
    block: str
    pulse: str
    omega_p: np.ndarray
    amp: np.ndarray
    codes: np.ndarray
    boundaries: pd.DataFrame
    options: dict
    extra: dict = field(default_factory=dict)
    inaccurate: int = 0
    bad_cells: np.ndarray = field(default_factory=lambda: np.zeros(0, np.intp))
    chunks_computed: int = 0
    chunks_skipped: int = 0
    wall_time_s: float = 0.0
    simulation_time_s: float = 0.0

    @classmethod
    def read(cls, folder) -> StoredMap:
        """The map in `folder`, from its manifest and the chunks on disk."""
        import pandas as pd

        folder = Path(folder)
        man = json.loads((folder / MANIFEST).read_text())
        omega_p, amp = np.array(man["omega_p"]), np.array(man["amp"])
        n_w, chunk = len(omega_p), man["chunk_cells"]
        codes = np.full(len(amp) * n_w, -1, np.int8)
        inaccurate, bad = 0, []
        for f in sorted((folder / "cells").glob("chunk-*.parquet")):
            c = int(f.stem.split("-")[1])
            col = _read_columns([f], ["outcome", "accurate"])
            codes[c * chunk : c * chunk + len(col["outcome"])] = col["outcome"]
            inaccurate += int((~col["accurate"]).sum())
            bad.append(c * chunk + np.flatnonzero(~col["accurate"]))
        extra = {"omega_p": np.zeros(0), "amp": np.zeros(0), "outcome": np.zeros(0, np.int8)}
        refined = folder / "cells" / "refined.parquet"
        if refined.exists():
            extra = _read_columns([refined], ["omega_p", "amp", "outcome", "accurate"])
            inaccurate += int((~extra["accurate"]).sum())
        bpath = folder / "boundaries.parquet"
        boundaries = pd.DataFrame(columns=_SEGMENT_COLUMNS)
        if bpath.exists():
            _check_readable(bpath, folder)
            boundaries = pd.read_parquet(bpath)
        return cls(
            folder=folder,
            block=man["block"],
            pulse=man["pulse"],
            omega_p=omega_p,
            amp=amp,
            codes=codes.reshape(len(amp), n_w),
            boundaries=boundaries,
            options=man["options"],
            extra=extra,
            inaccurate=inaccurate,
            bad_cells=np.concatenate(bad) if bad else np.zeros(0, np.intp),
        )

    def with_run(
        self, computed: int, skipped: int, wall: float, simulation: float = 0.0
    ) -> StoredMap:
        """This map with the figures of the run that produced it."""
        d = dict(self.__dict__)
        d.update(
            chunks_computed=computed,
            chunks_skipped=skipped,
            wall_time_s=wall,
            simulation_time_s=simulation,
        )
        return StoredMap(**d)

    @property
    def grid(self) -> np.ndarray:
        """Outcome names on the base grid, shape (len(amp), len(omega_p))."""
        return np.array(_OUTCOMES + ("",), dtype=object)[self.codes]

    @property
    def cells(self) -> pd.DataFrame:
        """All stored cells as one table (loads every chunk: for small maps and tests)."""
        import pandas as pd

        return pd.read_parquet(self.folder / "cells")

    def overturned(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the cell overturned."""
        return self.codes == _OUTCOMES.index("overturned")

    def undecided(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the map could not decide the cell."""
        return self.codes == _OUTCOMES.index("undecided")

    def overturn_fraction(self) -> float:
        """Share of grid cells that overturn (undecided cells do not count)."""
        return float(np.mean(self.overturned()))

    def undecided_fraction(self) -> float:
        """Share of grid cells the map could not decide."""
        return float(np.mean(self.undecided()))

    def min_overturn_amp(self) -> list:
        """As `OverturningMap.min_overturn_amp`, from the code grid and the refined cells."""
        over = _OUTCOMES.index("overturned")
        first = np.where(self.overturned(), self.amp[:, None], np.inf).min(axis=0)
        ex = self.extra
        b = self.boundaries[self.boundaries.high_outcome == "overturned"]
        out = []
        for j, w in enumerate(self.omega_p):
            f = min(
                first[j],
                ex["amp"][(ex["omega_p"] == w) & (ex["outcome"] == over)].min(initial=np.inf),
            )
            if not np.isfinite(f):
                out.append(None)
                continue
            below = b.amp_high[(b.omega_p == w) & (b.amp_high <= f + 1e-12)]
            out.append(float(below.min()) if not below.empty else float(f))
        return out

    def inaccurate_grid_cells(self) -> pd.DataFrame:
        """Grid cells whose run failed its accuracy check (``omega_p``, ``amp``)."""
        import pandas as pd

        n_w = len(self.omega_p)
        i = self.bad_cells
        return pd.DataFrame({"omega_p": self.omega_p[i % n_w], "amp": self.amp[i // n_w]})

    def n_simulations(self) -> int:
        """Cells simulated: the grid and the refined boundary cells."""
        return int(self.codes.size + len(self.extra["amp"]))

    def summary(self) -> dict:
        """JSON-ready summary, the keys of `OverturningMap.summary` plus the store's."""
        counts = np.bincount(self.codes[self.codes >= 0].ravel(), minlength=len(_OUTCOMES))
        opts = dict(self.options)
        return {
            "block": self.block,
            "pulse": self.pulse,
            "restitution": opts.get("restitution_name"),
            "restitution_value": opts.get("restitution_value"),
            "k": opts.get("k"),
            "omega_p": [float(w) for w in self.omega_p],
            "amp": [float(a) for a in self.amp],
            "min_overturn_amp": self.min_overturn_amp(),
            "overturn_fraction": self.overturn_fraction(),
            "undecided_fraction": self.undecided_fraction(),
            "outcomes": {k: int(counts[i]) for i, k in enumerate(_OUTCOMES)},
            "inaccurate": int(self.inaccurate),
            "n_simulations": self.n_simulations(),
            "wall_time_s": float(self.wall_time_s),
            "simulation_time_s": float(self.simulation_time_s),
            "wall_time_covers": WALL_TIME_COVERS,
            "options": {k: v for k, v in opts.items() if k != "restitution_name"},
            "store": {
                "folder": str(self.folder),
                "chunks_computed": self.chunks_computed,
                "chunks_skipped": self.chunks_skipped,
            },
        }
