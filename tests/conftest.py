"""Shared fixtures: paths to the repository and to the read-only shared data."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
GROUND_MOTIONS = SHARED / "data" / "ground_motions"
REFERENCE = SHARED / "data" / "reference"


IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")


def unavailable(reason: str):
    """Skip a test whose resource is missing here — but fail it in CI, where every
    resource must be present (`.ci/run` sets CI=true; a skip there would hide a gap)."""
    if IN_CI:
        pytest.fail(f"{reason} (CI=true: a resource missing in CI is a failure, not a skip)")
    pytest.skip(reason)


@pytest.fixture(scope="session")
def ground_motions() -> Path:
    """Folder of the real records (../shared/data/ground_motions); skip if absent (fail in CI)."""
    if not GROUND_MOTIONS.is_dir():
        unavailable(f"shared ground-motion records not found at {GROUND_MOTIONS}")
    return GROUND_MOTIONS


@pytest.fixture(scope="session")
def reference_data() -> Path:
    """Folder of other engines' outputs (../shared/data/reference, provenance in its
    SOURCES_rocking.md); skip if absent (fail in CI)."""
    if not REFERENCE.is_dir():
        unavailable(f"shared reference outputs not found at {REFERENCE}")
    return REFERENCE


def column_toml(tmp_path, heights, masses, name="custom", **replace) -> Path:
    """A column specimen file like S1 with other node heights and masses (no sensors)."""
    import re

    from multimass import specimens

    text = specimens.loader._bundled()["S1"].read_text()
    text = re.sub(r"\n\[sensors\][^\[]*", "\n", text)
    text = (
        text.replace("[0.06, 0.49, 0.93, 1.43, 1.93]", repr(list(heights)))
        .replace("[77.3, 6.2, 88.2, 8.2, 46.2]", repr(list(masses)))
        .replace('name = "S1"', f'name = "{name}"')
    )
    for old, new in replace.items():
        text = text.replace(old, new)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


class RaisingExcitation:
    """An excitation that raises inside solve_ivp after t = 0.3 s, as LSODA's event root
    search can (found by the benchmarks): a run must end 'failed' with the message."""

    duration, breakpoints = 1.0, ()

    def __call__(self, t):
        import numpy as np

        if np.ndim(t) == 0 and t > 0.3:
            raise ValueError("f(a) and f(b) must have different signs")
        return 0.0 * np.asarray(t) if np.ndim(t) else 0.0

    acceleration = __call__
