"""Every example script runs (STYLE.md: "Every example script runs in CI").

The gallery's scripts (examples/gallery/plot_*.py) run in the documentation build, which
stops on a failing one (.ci/run; tests/test_docs.py checks that it is so configured).
"""

import subprocess
import sys

import pytest

from tests.conftest import REPO

EXAMPLES = {
    "compare_trace.py": [],
    "choose_scenes.py": [],
}


def test_every_example_is_listed():
    assert {p.name for p in (REPO / "examples").glob("*.py")} == set(EXAMPLES)


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_example_runs(name, tmp_path):
    args = [a.format(tmp=tmp_path) for a in EXAMPLES[name]]
    done = subprocess.run(
        [sys.executable, str(REPO / "examples" / name), *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip()
