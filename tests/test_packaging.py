"""One import name: the distribution installs `multimass` and nothing else at the
top level of site-packages; the folders the design card keeps at the repository's top level
(modal/, impact_models/, specimens/) import only as multimass.modal, ... ."""

import shutil
import subprocess
import sys
import zipfile

import pytest

from tests.conftest import REPO


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    # built from a copy: setuptools writes build/ and *.egg-info into the tree it builds
    src = tmp_path_factory.mktemp("src") / "multimass"
    shutil.copytree(
        REPO,
        src,
        symlinks=True,
        ignore=shutil.ignore_patterns(
            ".git", "build", "*.egg-info", "__pycache__", "docs", "tests", "examples"
        ),
    )
    out = tmp_path_factory.mktemp("wheel")
    done = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "-q", "-w", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    (path,) = out.glob("multimass-*.whl")
    return path


def test_the_wheel_has_one_top_level_import_name(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert top == {"multimass"}
    for sub in (
        "modal",
        "impact_models",
        "specimens",
        "model",
        "inputs",
        "engines",
        "engines/nscd",
        "engines/fast",
        "analysis",
        "bench",
    ):
        assert f"multimass/{sub}/__init__.py" in names
    assert "multimass/specimens/data/S1.toml" in names
    assert not any(n.startswith("benchmarks/") for n in names)  # developer-only scripts


def test_installed_beside_a_package_named_modal_both_import(wheel, tmp_path):
    # `modal` is also the import name of a widely installed cloud SDK: installing multimass
    # must neither overwrite it nor be shadowed by it
    target = tmp_path / "site"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--no-deps",
            "-q",
            "--target",
            str(target),
            str(wheel),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    (target / "modal").mkdir()
    (target / "modal" / "__init__.py").write_text("WHO = 'the other modal'\n")
    code = (
        "import modal, multimass.modal as mm; "
        "print(modal.WHO); print(mm.__file__); print(mm.analyse('S1').rocking.freq_hz[0])"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={"PYTHONPATH": str(target), "PATH": ""},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    who, where, freq = done.stdout.split("\n")[:3]
    assert who == "the other modal" and where.startswith(str(target))
    assert abs(float(freq) - 20.50) < 0.01  # S1 uplifted mode 1 (README, 20.50 Hz)


@pytest.mark.parametrize("name", ["modal", "specimens", "impact_models"])
def test_no_bare_top_level_name_from_the_repository_root(name):
    done = subprocess.run(
        [sys.executable, "-c", f"import {name}"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode != 0
    assert f"installs as `multimass.{name}`; import that" in done.stderr


@pytest.mark.parametrize(
    "name, shared",
    [("specimens", ["errors"]), ("impact_models", ["errors"]), ("model.equations", [])],
)
def test_the_bottom_layers_load_nothing_else(name, shared):
    code = (
        f"import sys, multimass.{name}; "
        "print(sorted({m.split('.')[1] for m in sys.modules if m.startswith('multimass.')}))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO.parent, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr[-2000:]
    # the error family is shared; the package root loads only the finder of the old module
    # paths (`multimass._paths`, standard library alone)
    assert done.stdout.strip() == str(sorted({"_paths", name.split(".")[0], *shared}))


def test_no_module_is_named_like_the_public_name_it_holds():
    # `import multimass.simulate as m` used to give the function; with lazy loading a module
    # named like a public function shadows it (multimass.simulate became the module)
    import importlib
    import pkgutil

    import multimass

    clashes = []
    for pkg_name in (
        "multimass",
        "multimass.engines.nscd",
        "multimass.modal",
        "multimass.sweeps",
        "multimass.scenes",
        "multimass.engines.fast",
        "multimass.specimens",
        "multimass.impact_models",
        "multimass.cli",
        "multimass.bench",
    ):
        pkg = importlib.import_module(pkg_name)
        subs = {m.name for m in pkgutil.iter_modules(pkg.__path__)}
        clashes += [
            f"{pkg_name}.{n}"
            for n in getattr(pkg, "__all__", ())
            if n in subs and not isinstance(getattr(pkg, n), type(multimass))
        ]
    assert not clashes, clashes
