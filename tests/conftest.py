"""Shared fixtures: paths to the repository and to the read-only shared data."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
GROUND_MOTIONS = SHARED / "data" / "ground_motions"


@pytest.fixture(scope="session")
def ground_motions() -> Path:
    """Folder of the real records (../shared/data/ground_motions); skip if absent."""
    if not GROUND_MOTIONS.is_dir():
        pytest.skip(f"shared ground-motion records not found at {GROUND_MOTIONS}")
    return GROUND_MOTIONS
