"""The documentation: the API reference (docs/api) names every public module, so none is
forgotten silently; every gallery example has a title and a guide page that links it; no
page speaks of issue numbers.

The Sphinx build itself runs in .ci/run with warnings as errors, and runs every gallery
example (sphinx-gallery stops the build on a failing one); these checks read the sources
only and need no Sphinx.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs" / "api"

# The modules a user scripts with or reads about in the guide: the reference documents each.
REQUIRED = (
    "multimass",
    "multimass.specimens",
    "multimass.impact_models",
    "multimass.modal",
    "multimass.simulation",
    "multimass.sweeps",
    "multimass.scenes",
    "multimass.engines.nscd",
    "multimass.engines.poisson_block",
    "multimass.engines.flexible_oscillator",
    "multimass.engines.newmark",
    "multimass.checks",
    "multimass.cost",
    "multimass.progress",
    "multimass.validation",
    "multimass.errors",
    "multimass.inputs.records",
    "multimass.inputs.traces",
    "multimass.analysis.trace_metrics",
    "multimass.inputs.excitations",
    "multimass.model.structure",
    "multimass.inputs.units",
    "multimass.cli",
)

# Packages whose submodules are not documented one by one: the cli's sub-command
# modules are shown by the command-line page (docs/api/cli.rst).
NOT_RECURSIVE = {"multimass.cli"}


def _autosummaries() -> list[tuple[set[str], list[str]]]:
    """(options, entries) of every ``.. autosummary::`` block of the hand-written pages."""
    blocks = []
    for page in sorted(DOCS.glob("*.rst")):
        text = page.read_text(encoding="utf-8")
        for body in re.findall(r"^\.\. autosummary::\n((?:[ \t]+\S.*\n|[ \t]*\n)*)", text, re.M):
            options = set(re.findall(r"^\s+:([\w-]+):", body, re.M))
            entries = re.findall(r"^\s+(?!:)(\S+)\s*$", body, re.M)
            blocks.append((options, entries))
    return blocks


def _documented() -> dict[str, bool]:
    """Module name -> whether its block documents its submodules (``:recursive:``)."""
    out: dict[str, bool] = {}
    for options, entries in _autosummaries():
        for name in entries:
            out[name] = out.get(name, False) or "recursive" in options
    return out


def _public_modules() -> dict[str, bool]:
    """The package's public top-level modules -> whether each is a package (from the files)."""
    out = {"multimass": True}
    for path in (ROOT / "multimass").iterdir():
        if path.name.startswith(("_", ".")):
            continue
        if path.suffix == ".py":
            out[f"multimass.{path.stem}"] = False
        elif path.is_dir() and (path / "__init__.py").is_file():  # symbolic links included
            out[f"multimass.{path.name}"] = True
    return out


def test_the_required_modules_are_documented():
    documented = _documented()

    def covered(m: str) -> bool:  # listed, or inside a package listed with :recursive:
        return m in documented or any(m.startswith(d + ".") and r for d, r in documented.items())

    missing = [m for m in REQUIRED if not covered(m)]
    assert not missing, f"docs/api does not document {missing}"


def test_every_public_module_is_documented():
    documented = _documented()
    missing = sorted(set(_public_modules()) - set(documented))
    assert not missing, f"add these public modules to docs/api/reference.rst: {missing}"


def test_packages_document_their_submodules():
    documented = _documented()
    flat = sorted(
        name
        for name, is_package in _public_modules().items()
        if is_package
        and name != "multimass"  # its modules are listed one by one
        and name not in NOT_RECURSIVE
        and not documented.get(name, False)
    )
    assert not flat, f"list these packages under an autosummary with :recursive: {flat}"


def test_every_documented_module_exists():
    for name in _documented():
        parts = name.split(".")
        assert parts[0] == "multimass", name
        base = ROOT.joinpath(*parts)
        assert base.with_suffix(".py").is_file() or (base / "__init__.py").is_file(), (
            f"docs/api documents {name}, which does not exist"
        )


def test_the_docs_build_is_installed_and_strict():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"][
        "optional-dependencies"
    ]
    names = {re.split(r"[<>=!~\[ ]", req, maxsplit=1)[0] for req in extras["docs"]}
    assert {"sphinx", "numpydoc", "myst-parser"} <= names
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert 'pip install -e ".[docs]"' in ci
    assert re.search(r"^sphinx-build -W .* docs ", ci, re.M), "the docs build must use -W"
    names_extra = {"pydata-sphinx-theme", "sphinx-gallery"}
    assert names_extra <= names, "the docs extra installs the theme and the gallery"


# --- the user guide and the gallery -------------------------------------------------------

GALLERY = ROOT / "examples" / "gallery"
GUIDE = ROOT / "docs" / "guide"


def _gallery() -> list[Path]:
    return sorted(GALLERY.glob("plot_*.py"))


def test_the_docs_build_runs_the_gallery():
    conf = (ROOT / "docs" / "conf.py").read_text(encoding="utf-8")
    assert '"sphinx_gallery.gen_gallery"' in conf
    assert '"abort_on_example_error": True' in conf  # a failing example fails the build
    assert _gallery(), "examples/gallery has no plot_*.py"
    assert (GALLERY / "GALLERY_HEADER.rst").is_file()


def test_every_gallery_example_has_a_title_and_a_guide_page():
    guide = "\n".join(p.read_text(encoding="utf-8") for p in GUIDE.glob("*.md"))
    for script in _gallery():
        text = script.read_text(encoding="utf-8")
        doc = re.match(r'"""\n(.+)\n(=+)\n', text)
        assert doc and len(doc.group(2)) >= len(doc.group(1)), f"{script.name}: no title"
        assert "# %%" in text, f"{script.name}: no cells"
        ref = f"sphx_glr_auto_examples_{script.name.replace('.', '_')}"
        assert ref.removesuffix("_py") + ".py" in guide, f"no guide page links {script.name}"


def test_the_guide_has_a_page_per_question():
    pages = {p.stem for p in GUIDE.glob("*.md")}
    assert {
        "getting_started",
        "structure",
        "vibrates",
        "rocks",
        "blocks",
        "traces",
        "suites",
        "scaling",
        "speed",
        "theory",
    } <= pages
    index = (GUIDE / "index.rst").read_text(encoding="utf-8")
    assert all(p in index for p in pages - {"theory"})


def test_no_page_speaks_of_issue_numbers():
    files = [ROOT / "README.md", *ROOT.joinpath("docs").rglob("*.md")]
    files += [*ROOT.joinpath("docs").rglob("*.rst"), *ROOT.joinpath("examples").rglob("*.py")]
    found = [
        f"{f.relative_to(ROOT)}: {m.group(0)}"
        for f in files
        if "generated" not in f.parts and "auto_examples" not in f.parts
        for m in re.finditer(r"issue [0-9]+", f.read_text(encoding="utf-8"), re.I)
    ]
    assert not found, found
