"""`multimass warm-up`: every kernel compiled or loaded on purpose, and said so."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import multimass
from multimass.cli import main
from multimass.cli.warmup_cmd import GROUPS
from multimass.engines.fast import compile as fc

SOURCES = ("compiled", "disk cache", "in memory")


def test_help_says_what_it_does_and_where_the_cache_is(capsys):
    assert main(["warm-up", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for words in ("NUMBA_CACHE_DIR", "MULTIMASS_QUIET", "read-only", "multimass/numba", "--json"):
        assert words in text
    assert all(f"{name}:" in text for name in GROUPS)


def test_unknown_group_is_refused(capsys):
    assert main(["warm-up", "--only", "everything"]) == 2
    assert "invalid choice" in capsys.readouterr().err


def test_json_reports_each_group(capsys):
    assert main(["warm-up", "--only", "fast", "--only", "newmark", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [g["group"] for g in out["groups"]] == ["fast", "newmark"]
    for g in out["groups"]:
        assert g["source"] in SOURCES and g["seconds"] >= 0.0
        assert Path(g["cache_dir"]).is_dir()
        assert (g["kernels_compiled"] > 0) == (g["source"] == "compiled")
    assert out["cache"]["reason"] == fc.CACHE.reason
    assert out["seconds"] >= max(g["seconds"] for g in out["groups"])


def test_text_names_the_group_what_it_did_and_the_cache(capsys):
    assert main(["warm-up", "--only", "newmark"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("the Newmark kernel") and lines[0].endswith("[newmark]")
    assert any(done in lines[0] for done in ("compiled in", "loaded from the cache", "memory"))
    assert Path(lines[1].split("cache: ")[1]).is_dir()
    assert lines[-1].startswith("ready in") and fc.CACHE.reason in lines[-1]


_RUN = "import sys; from multimass.cli import main; sys.exit(main(sys.argv[1:]))"


@pytest.mark.slow  # a cold compile (~15-30 s); test_compile.py covers the notice and the cache
def test_cold_compile_then_load_in_fresh_processes(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != fc.QUIET_ENV}
    env["NUMBA_CACHE_DIR"] = str(tmp_path)  # an empty cache: a new machine
    runs = []
    for _ in range(2):
        done = subprocess.run(
            [sys.executable, "-c", _RUN, "warm-up", "--only", "fast", "--json"],
            env=env,
            capture_output=True,
            text=True,
            check=True,
            timeout=600,
        )
        runs.append((json.loads(done.stdout)["groups"][0], done.stderr))
    (cold, cold_err), (warm, warm_err) = runs
    n_kernels = len(fc._kernels_of(f"multimass.engines.fast.{m}" for m in fc._KERNEL_MODULES))
    assert cold["source"] == "compiled"
    # one compilation per kernel: a second specialisation of any kernel would count twice
    assert cold["kernels_compiled"] == n_kernels
    assert cold["cache_dir"].startswith(str(tmp_path))
    assert "multimass: compiling the fast kernels once for this machine" in cold_err
    assert "multimass: compiled the fast kernels in" in cold_err
    assert warm["source"] == "disk cache" and warm["kernels_compiled"] == 0
    assert "compil" not in warm_err  # loading is silent


def test_writes_the_bytecode_python_does_not_write_itself(capsys):
    # PYTHONDONTWRITEBYTECODE (container images, this suite's CI) leaves the package's
    # modules to be compiled from source at every import; warm-up writes their bytecode,
    # whose header Python checks against the source (importlib: mtime and size)
    import importlib.util

    import multimass.inputs.units as module

    source = Path(module.__file__)
    pyc = Path(importlib.util.cache_from_source(str(source)))
    pyc.unlink(missing_ok=True)
    assert main(["warm-up", "--only", "newmark", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["bytecode"]
    assert out["written"] and Path(out["folder"]) == Path(multimass.__file__).parent
    header, stat = pyc.read_bytes()[:16], source.stat()
    assert header[:4] == importlib.util.MAGIC_NUMBER
    assert int.from_bytes(header[8:12], "little") == int(stat.st_mtime) & 0xFFFFFFFF
    assert int.from_bytes(header[12:16], "little") == stat.st_size & 0xFFFFFFFF
    assert main(["warm-up", "--only", "newmark"]) == 0
    assert "bytecode of multimass's modules up to date" in capsys.readouterr().out
