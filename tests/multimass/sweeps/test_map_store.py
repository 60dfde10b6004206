"""Overturning maps streamed to Parquet chunks and resumed.

A map forced to store must give the in-memory map cell for cell (the same compiled
batch, however the cells are cut into chunks), an interrupted run must compute only
the chunks that are missing, and a folder holding another map must be refused.
"""

import json

import numpy as np
import pandas as pd
import pytest

from multimass.cli import main
from multimass.sweeps import map_store, maps
from multimass.sweeps.map_store import MapStoreMismatch, StoredMap
from multimass.sweeps.maps import overturning_map

GRID = dict(omega_p=np.linspace(0.5, 10, 12), amp=np.linspace(0.25, 8, 10))
N_CELLS = 120
CHUNK = 25  # 5 chunks: 4 of 25 cells and one of 20


@pytest.fixture
def small_chunks(monkeypatch):
    monkeypatch.setattr(maps, "STORE_CHUNK_CELLS", CHUNK)


def _sorted(cells: pd.DataFrame) -> pd.DataFrame:
    cells = cells.assign(outcome=cells.outcome.astype(str))
    return cells.sort_values(["grid", "amp", "omega_p"], kind="stable").reset_index(drop=True)


def _counting(monkeypatch):
    """Count the grid cells that the store's chunks send to `simulate_cells`."""
    seen = {"cells": 0}
    real = maps.simulate_cells

    def count(pairs, *args):
        if args[-1] is None:  # the store's chunks carry no progress label
            seen["cells"] += len(pairs)
        return real(pairs, *args)

    monkeypatch.setattr(maps, "simulate_cells", count)
    return seen


def test_stored_map_equals_in_memory_map(tmp_path, small_chunks):
    mem = overturning_map("B6M", "sine", refine=1, executor="serial", **GRID)
    stored = overturning_map("B6M", "sine", refine=1, executor="serial", store=tmp_path, **GRID)
    assert isinstance(stored, StoredMap)
    assert len(list((tmp_path / "cells").glob("chunk-*.parquet"))) == 5
    back = pd.read_parquet(tmp_path / "cells")  # pandas reads the folder as one dataset
    pd.testing.assert_frame_equal(_sorted(back), _sorted(mem.cells), check_exact=True)
    np.testing.assert_array_equal(stored.grid, mem.grid)
    pd.testing.assert_frame_equal(stored.boundaries, mem.boundaries)
    a, b = mem.summary(), stored.summary()
    for key in ("wall_time_s", "simulation_time_s", "options"):
        a.pop(key), b.pop(key)
    assert b.pop("store")["chunks_computed"] == 5
    assert a == b


class _Interrupt(KeyboardInterrupt):
    pass


def test_interrupted_map_resumes_missing_chunks_only(tmp_path, monkeypatch, small_chunks):
    real_write = map_store._write_chunk
    written = []

    def write_then_stop(path, table):
        if len(written) == 2:
            raise _Interrupt  # Ctrl-C while the third chunk is being written
        real_write(path, table)
        written.append(path.name)

    monkeypatch.setattr(map_store, "_write_chunk", write_then_stop)
    with pytest.raises(_Interrupt):
        overturning_map("B6M", "cosine", executor="serial", store=tmp_path, **GRID)
    assert sorted(p.name for p in (tmp_path / "cells").glob("*")) == written
    assert not list((tmp_path / "cells").glob("*.tmp"))  # nothing half-written

    monkeypatch.setattr(map_store, "_write_chunk", real_write)
    seen = _counting(monkeypatch)
    resumed = overturning_map("B6M", "cosine", executor="serial", store=tmp_path, **GRID)
    assert (resumed.chunks_computed, resumed.chunks_skipped) == (3, 2)
    assert seen["cells"] == N_CELLS - 2 * CHUNK  # the finished chunks are not recomputed

    seen["cells"] = 0
    again = overturning_map("B6M", "cosine", executor="serial", store=tmp_path, **GRID)
    assert (again.chunks_computed, again.chunks_skipped, seen["cells"]) == (0, 5, 0)

    mem = overturning_map("B6M", "cosine", executor="serial", **GRID)
    pd.testing.assert_frame_equal(
        _sorted(pd.read_parquet(tmp_path / "cells")), _sorted(mem.cells), check_exact=True
    )


@pytest.mark.parametrize(
    "change, field",
    [
        (dict(amp=np.linspace(0.25, 8, 11)), "amp"),
        (dict(restitution="housner"), "options"),
        (dict(pulse="cosine"), "pulse"),
    ],
)
def test_other_arguments_into_the_same_folder_are_refused(tmp_path, small_chunks, change, field):
    args = dict(pulse="sine", executor="serial", store=tmp_path) | GRID
    overturning_map("B6M", **args)
    with pytest.raises(MapStoreMismatch, match=f"differ in: .*{field}.*new --out folder"):
        overturning_map("B6M", **(args | change))


def test_cli_streams_resumes_and_refuses(tmp_path, capsys):
    base = ["stability", "B6M", "--executor", "serial", "--omega-p", "0.5:10:8"]
    argv = base + ["--amp", "0.25:8:8", "--store", "--json", "--out", str(tmp_path)]
    assert main(argv) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["store"]["chunks_computed"] == 1
    assert (tmp_path / "manifest.json").exists()
    assert (tmp_path / "B6M_sine_modified_map.png").exists()
    assert not (tmp_path / "B6M_sine_modified_cells.csv").exists()
    assert len(pd.read_parquet(tmp_path / "cells").query("grid")) == 64
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["store"]["chunks_skipped"] == 1
    assert main(base + ["--amp", "0.25:8:9", "--store", "--out", str(tmp_path)]) == 2
    assert "holds a map computed with other arguments" in capsys.readouterr().err


def test_cli_large_map_needs_an_output_folder(capsys):
    assert main(["stability", "B6M", "--omega-p", "1:2:600", "--amp", "1:2:600"]) == 2
    assert "streams to disk: give `--out DIR`" in capsys.readouterr().err


def test_cli_threshold_is_the_store_threshold():
    from multimass.cli import stability_cmd

    assert stability_cmd.STORE_MIN_CELLS == map_store.STORE_MIN_CELLS


def test_resuming_over_a_corrupted_chunk_names_it_and_the_fix(tmp_path, small_chunks, capsys):
    """A chunk whose bytes are not Parquet (a disk full, a copy cut short) is reported
    before any new work, in one line naming the file, that it is corrupted and the fix
    (delete it to recompute it, or start afresh) — not pyarrow's "magic bytes not found"
    in a traceback. Deleting it, as the message says, recomputes it."""
    argv = ["stability", "B6M", "--executor", "serial", "--omega-p", "0.5:10:12"]
    argv += ["--amp", "0.25:8:10", "--store", "--json", "--out", str(tmp_path)]
    assert main(argv) == 0
    capsys.readouterr()
    bad = tmp_path / "cells" / "chunk-00001.parquet"
    bad.write_bytes(b"not a parquet file")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert f"{bad}: a chunk of cells is corrupted" in err
    assert "delete that file and run the same command again" in err and "start afresh" in err
    with pytest.raises(map_store.InputError, match="chunk-00001.parquet: a chunk of cells is"):
        StoredMap.read(tmp_path)
    bad.unlink()
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["store"]["chunks_computed"] == 1
