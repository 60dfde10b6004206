"""Adaptive overturning maps: simulate only the cells near outcome boundaries.

The rule (`adaptive_codes`), on a grid of n_a × n_w cells and a coarse spacing s = 2^K:

1. Compute the coarse lattice: every s-th row and column, plus the last of each.
   Consecutive lattice lines bound the level-s blocks.
2. At each level h = s, s/2, ..., 2: a block is *mixed* when the computed cells in it
   (corners, and any computed cell on its edges or inside) do not all share one class.
   `overturning_map` classes a cell by its outcome (no rocking, rest, undecided) and an
   overturned cell also by its overturning mode, the number of impacts before it
   overturned: paper 004's thin safe bands and islands lie between overturning modes,
   so two overturned corners of different modes mark a block to refine even when no
   corner is safe (with outcomes alone, single-cell islands inside the overturned
   region of the 64 × 64 B6M sine map are missed; with modes, none). Every mixed
   block and its `halo` ring of neighbouring blocks at that level are refined: the
   cells of the level-h/2 lattice in them are computed. New cells may lie on the edges
   of blocks judged uniform, so the test is repeated until no more blocks turn mixed;
   the refined blocks split into their level-h/2 children, the others are kept whole.
3. Final check: a kept block any of whose computed cells (corners, edges — e.g. cells
   that a refined neighbour computed later, at a finer level — or interior) disagree
   is computed cell by cell; repeated until every kept block is uniform.
4. The cells never computed take the class of their kept block, whose computed cells
   all agree.

Guarantee: a region of one class that contains an s × s square of cells contains a
coarse-lattice cell, so it is found. A smaller island is found when it reaches a
lattice cell or a cell that a refinement computes — in particular when it lies within
`halo` blocks of a boundary found at some level; an island narrower than the spacing
of its level, lying entirely inside a block whose computed cells all agree and far
from any other boundary, is missed. The coarse spacing is chosen from the smallest
island the map must not miss: ``coarse = s`` finds every island of at least s × s
cells (default 8); s = 1 is the brute-force map.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .map_cells import OUTCOMES
from .map_store import grid_segments

__all__ = [
    "adaptive_codes",
    "adaptive_cells",
    "check_coarse",
    "count_islands",
    "ADAPTIVE_COARSE",
    "ADAPTIVE_HALO",
]

#: Default coarse spacing of an adaptive map (cells; a power of 2).
ADAPTIVE_COARSE = 8
#: Default ring of neighbouring blocks refined with a mixed block.
ADAPTIVE_HALO = 1


def check_coarse(coarse) -> int:
    """`coarse` as an int, if it is a power of 2 (1, 2, 4, ...)."""
    ok = not isinstance(coarse, bool) and isinstance(coarse, (int, np.integer, float))
    if not ok or int(coarse) != coarse or coarse < 1 or int(coarse) & (int(coarse) - 1):
        raise InputError(f"`coarse` = {coarse!r}: expected a power of 2 (1, 2, 4, 8, ...)")
    return int(coarse)


def _lattice(n: int, h: int) -> np.ndarray:
    return np.unique(np.r_[np.arange(0, n, h), n - 1])


def _mixed_blocks(codes: np.ndarray, blocks: list) -> list:
    """Whether each closed block (a0, a1, w0, w1) is mixed: the computed cells in it (codes
    ≥ 0) do not all share one class. Array operations over the blocks of each shape."""
    flags = [False] * len(blocks)
    shapes: dict = {}
    for k, (a0, a1, w0, w1) in enumerate(blocks):
        shapes.setdefault((a1 - a0, w1 - w0), []).append(k)
    for (da, dw), ks in shapes.items():
        at = np.array([(blocks[k][0], blocks[k][2]) for k in ks], dtype=np.intp)
        rows = at[:, :1, None] + np.arange(da + 1)[None, :, None]
        cols = at[:, None, 1:] + np.arange(dw + 1)[None, None, :]
        sub = codes[rows, cols]  # (blocks, da + 1, dw + 1)
        known = sub >= 0
        top = np.where(known, sub, -1).max(axis=(1, 2))
        low = np.where(known, sub, np.iinfo(codes.dtype).max).min(axis=(1, 2))
        for k, m in zip(ks, ((top >= 0) & (low != top)).tolist()):
            flags[k] = m
    return flags


def _points(b, half, n_a, n_w):
    """The cells of the level-`half` lattice in the closed block `b`."""
    a0, a1, w0, w1 = b
    la = [i for i in (a0, a0 + half, a1) if i <= a1]
    lw = [j for j in (w0, w0 + half, w1) if j <= w1]
    return [(i, j) for i in la for j in lw]


def _children(b, half):
    a0, a1, w0, w1 = b
    sa = [(a0, a1)] if a1 - a0 <= half else [(a0, a0 + half), (a0 + half, a1)]
    sw = [(w0, w1)] if w1 - w0 <= half else [(w0, w0 + half), (w0 + half, w1)]
    return [(p, q, r, s) for p, q in sa for r, s in sw if q - p > 1 or s - r > 1]


def adaptive_codes(
    n_a: int, n_w: int, evaluate, coarse: int = ADAPTIVE_COARSE, halo: int = ADAPTIVE_HALO
):
    """Outcome codes of an n_a × n_w grid, computing cells only near boundaries.

    Parameters
    ----------
    n_a, n_w : int
        Grid shape (amplitude rows, ω/p columns).
    evaluate : callable
        ``evaluate(index)`` with `index` an (m, 2) int array of (row, column) cells returns
        their m outcome codes (integers ≥ 0); called once per refinement pass.
    coarse : int
        Coarse spacing s, a power of 2 (see the module docstring for the guarantee).
    halo : int
        Rings of neighbouring blocks refined with each mixed block.

    Returns
    -------
    codes : ndarray of int8, shape (n_a, n_w)
    computed : ndarray of bool, shape (n_a, n_w)
        The cells that were simulated.
    """
    coarse = check_coarse(coarse)
    if isinstance(halo, bool) or int(halo) != halo or halo < 0:
        raise InputError(f"`halo` = {halo!r}: expected an integer ≥ 0")
    codes = np.full((n_a, n_w), -1, np.int32)

    def compute(cells) -> int:
        idx = np.array(sorted({c for c in cells if codes[c] < 0}), dtype=np.intp).reshape(-1, 2)
        if len(idx):
            codes[idx[:, 0], idx[:, 1]] = evaluate(idx)
        return len(idx)

    h = int(coarse)
    la, lw = _lattice(n_a, h), _lattice(n_w, h)
    compute([(i, j) for i in la for j in lw])
    blocks = [(p, q, r, s) for p, q in zip(la, la[1:]) for r, s in zip(lw, lw[1:])]
    blocks = [tuple(int(x) for x in b) for b in blocks if b[1] - b[0] > 1 or b[3] - b[2] > 1]
    kept = []
    while h >= 2 and blocks:
        half = h // 2
        by_start = {(b[0], b[2]): b for b in blocks}
        refine: set = set()
        while True:
            open_ = [b for b in blocks if b not in refine]
            mixed = [b for b, m in zip(open_, _mixed_blocks(codes, open_)) if m]
            if not mixed:
                break
            grow = set(mixed)
            for a0, _, w0, _ in mixed:
                for da in range(-halo, halo + 1):
                    for dw in range(-halo, halo + 1):
                        nb = by_start.get((a0 + da * h, w0 + dw * h))
                        if nb is not None:
                            grow.add(nb)
            grow -= refine
            refine |= grow
            compute([p for b in sorted(grow) for p in _points(b, half, n_a, n_w)])
        kept += [(b, h) for b in blocks if b not in refine]
        blocks = [c for b in sorted(refine) for c in _children(b, half)]
        h = half
    while True:  # final check of the kept blocks: corners, edges and interior
        bad = [b for (b, _), m in zip(kept, _mixed_blocks(codes, [b for b, _ in kept])) if m]
        if not bad:
            break
        bad_set = set(bad)
        kept = [(b, lv) for b, lv in kept if b not in bad_set]
        compute(
            [(i, j) for a0, a1, w0, w1 in bad for i in range(a0, a1 + 1) for j in range(w0, w1 + 1)]
        )
    computed = codes >= 0
    for (a0, a1, w0, w1), _ in kept:
        sub = codes[a0 : a1 + 1, w0 : w1 + 1]
        known = sub[sub >= 0]
        sub[sub < 0] = known[0]
    if (codes < 0).any():  # cannot happen: every cell lies in a kept block or was computed
        raise RuntimeError("adaptive map left cells without an outcome")
    return codes, computed


def adaptive_cells(omega_p, amp, coarse, rounds, simulate, bisect, table):
    """Cells (a table of every grid cell, ``computed`` True where simulated, numeric columns
    missing elsewhere, plus the refined boundary cells) and boundary segments of an
    adaptive map (`adaptive_codes`). ``simulate(pairs, desc)`` gives `map_cell` results,
    ``bisect`` and ``table`` are `maps._bisect` and `maps._cells_table`."""
    import pandas as pd  # here: the other maps need no pandas at import

    n_a, n_w = len(amp), len(omega_p)
    results: dict[int, tuple] = {}
    code = {name: i for i, name in enumerate(OUTCOMES)}

    def evaluate(index):
        pairs = [(float(omega_p[j]), float(amp[i])) for i, j in index.tolist()]
        out = simulate(pairs, "adaptive map")
        for (i, j), r in zip(index.tolist(), out):
            results[i * n_w + j] = r
        # an overturned cell's class is its overturning mode (impacts before it overturned):
        # thin safe bands lie between modes (paper 004, Figs 4-9)
        return [code[r[0]] if r[0] != "overturned" else len(OUTCOMES) + r[3] for r in out]

    classes, computed = adaptive_codes(n_a, n_w, evaluate, coarse)
    codes = np.where(classes >= len(OUTCOMES), code["overturned"], classes)
    flat = np.array(sorted(results), dtype=np.intp)
    got = [results[i] for i in flat.tolist()]
    n = n_a * n_w
    t_over, theta = np.full(n, np.nan), np.full(n, np.nan)
    impacts, missing, accurate = np.zeros(n, np.int64), np.ones(n, bool), np.ones(n, bool)
    if got:
        t_over[flat] = [r[1] for r in got]
        theta[flat] = [r[2] for r in got]
        impacts[flat], missing[flat] = [r[3] for r in got], False
        accurate[flat] = [bool(r[5]) for r in got]
    impacts = pd.arrays.IntegerArray(impacts, missing)  # Int64: missing where not computed
    cells = pd.DataFrame(
        {
            "omega_p": np.tile(np.asarray(omega_p, float), n_a),
            "amp": np.repeat(np.asarray(amp, float), n_w),
            "outcome": np.array(OUTCOMES, dtype=object)[codes.ravel()],
            "overturn_time": t_over,
            "theta_max_over_alpha": theta,
            "n_impacts": impacts,
            "accurate": accurate,
            "grid": True,
            "computed": computed.ravel(),
        }
    )
    extra, segments = bisect(grid_segments(codes, omega_p, amp), rounds, simulate)
    if extra:
        ew, ea, er = zip(*extra)
        rows = table(ew, ea, er, False)
        rows["n_impacts"] = rows["n_impacts"].astype("Int64")
        rows["computed"] = True
        cells = pd.concat([cells, rows], ignore_index=True)
    return cells, segments


def count_islands(grid, inside: str = "rest", outside: str = "overturned") -> int:
    """Connected regions (4-neighbour) of `inside` cells whose every neighbour outside the
    region is an `outside` cell and which do not touch the grid's edge: the safe islands of
    an overturning map."""
    from scipy import ndimage

    grid = np.asarray(grid)
    labels, n = ndimage.label(grid == inside)
    if n == 0:
        return 0
    border = np.zeros(grid.shape, bool)
    border[[0, -1], :] = border[:, [0, -1]] = True
    ok = np.ones(n + 1, bool)
    ok[np.unique(labels[border])] = False
    for shift in ((1, 0), (-1, 0), (0, 1), (0, -1)):  # labels next to a non-`outside` cell
        nb = np.roll(grid, shift, axis=(0, 1))
        lab = labels
        bad = (lab > 0) & (nb != outside) & (np.roll(labels, shift, axis=(0, 1)) != lab)
        ok[np.unique(lab[bad])] = False
    ok[0] = False
    return int(ok.sum())
