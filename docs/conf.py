"""Sphinx configuration of the documentation site: user guide, gallery, theory, reference.

Build from the repository's root (``.ci/run`` does, with warnings as errors)::

    pip install -e ".[docs]"
    sphinx-build -W --keep-going -b html docs docs/_build/html

The guide's pages are in ``docs/guide/``; the gallery's scripts in ``examples/gallery/``
run at build time (sphinx-gallery) and make their own figures, written to
``docs/auto_examples/`` (not committed). The examples are short (seconds each once the
compiled kernels are cached); ``MULTIMASS_DOCS_NO_GALLERY=1`` skips running them, for quick
edits of the prose (the gallery's pages are then built without output; CI runs them all). The API pages are
generated from the docstrings (numpydoc style) by autosummary into
``docs/api/generated/`` (not committed); the command-line page is the ``--help`` text of
every sub-command, captured at build time from `multimass.cli.build_parser`. Nothing is
fetched from the network (no intersphinx).
"""

from __future__ import annotations

import argparse
import ast
import importlib
import logging
import os
import pkgutil
import re
import shutil
import sys
from importlib.metadata import version as _version
from pathlib import Path

from docutils import nodes
from sphinx.util import logging as sphinx_logging
from sphinx.util.docutils import SphinxDirective

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))  # local extensions (mathjax_offline)
ROOT = HERE.parent  # the repository's root: examples/, README.md

# -- project ---------------------------------------------------------------------------
project = "multimass"
author = "the multimass developers"
copyright = "the multimass developers"
release = _version("multimass")
version = release

# -- general ---------------------------------------------------------------------------
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "mathjax_offline",  # docs/_ext: MathJax 3 copied into _static, equations render offline
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
# The folders of long benchmarks hold their own Markdown (written by the commands that
# regenerate them); the guide's pages include what they show (``{include}``), so they are
# not pages of their own. auto_examples/*.ipynb and the gallery's own files are not pages.
exclude_patterns = [
    "_build",
    "_templates",
    "bench/*.md",
    "nscd/*.md",
    "scaling/*.md",
    "identify/coverage/**",
    "suites/**",
    "spectra/**",
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.md5",
    "auto_examples/*.json",
    "auto_examples/*.zip",
]
# `name` in a docstring is a cross-reference when it names a documented object (plain
# code otherwise: unresolved references are not errors unless nitpicky is on)
default_role = "py:obj"
nitpicky = False

# -- autodoc / autosummary -------------------------------------------------------------
autosummary_generate = True
autosummary_generate_overwrite = True
autosummary_imported_members = False
autosummary_ignore_module_all = False  # a module's public names are its __all__
# autosummary imports every submodule of a package it lists; multimass.engines.fast.preload
# compiles the numba kernels when imported (up to a minute with a cold cache), so it gets
# a stand-in, which autosummary skips (it is left out of the pages: _NOT_DOCUMENTED)
autosummary_mock_imports = ["multimass.engines.fast.preload"]
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"  # numpydoc's Parameters sections give the types
autodoc_inherit_docstrings = False  # no numpy/stdlib docstrings on overridden methods
add_module_names = False

# -- numpydoc --------------------------------------------------------------------------
numpydoc_show_class_members = False  # the class template lists the members (autodoc)
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True  # Attributes as a field list: no duplicate objects
numpydoc_xref_param_type = False

# -- myst (Markdown pages and the benchmarks' own tables) ---------------------------------------------------
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# -- html ------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"multimass {release}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "header_links_before_dropdown": 6,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "changelog": []}
html_static_path: list[str] = []
html_show_sourcelink = False

# -- the gallery (sphinx-gallery) ------------------------------------------------------
# Every script examples/gallery/plot_*.py runs at build time; a failing example fails the
# build. They are short (a few seconds each once the compiled kernels are cached).
sphinx_gallery_conf = {
    "examples_dirs": [str(ROOT / "examples" / "gallery")],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "plot_gallery": os.environ.get("MULTIMASS_DOCS_NO_GALLERY", "") != "1",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "show_signature": False,
    "reset_modules": ("matplotlib",),
    "capture_repr": ("_repr_html_", "__repr__"),
    "min_reported_time": 1,
    # each function's reference page lists the examples that call it (minigallery)
    "doc_module": ("multimass",),
    "backreferences_dir": "api/generated/backreferences",
}

# -- modules whose docstrings still warn -----------------------------------------------
# Modules whose docstrings are known to warn and cannot be fixed in the same change
# (empty: every docstring builds cleanly). Warnings located in their docstrings, or quoting
# them on a generated page (an autosummary line is a docstring's first line), are dropped,
# module by module; every other warning fails the build (-W). Once a module's docstrings are fixed,
# the build fails with "... no longer warns: remove it": take it out of this tuple.
WARNINGS_TOLERATED_IN: tuple[str, ...] = ()


# -- the command line --------------------------------------------------------------------
class CommandHelp(SphinxDirective):
    """``.. multimass-help::`` — ``multimass --help`` and each sub-command's help.

    The text is produced at build time by `multimass.cli.build_parser`, so the page always
    matches the installed command line; one section per sub-command.
    """

    has_content = False

    def run(self) -> list[nodes.Node]:
        from multimass.cli import build_parser

        previous = os.environ.get("COLUMNS")
        os.environ["COLUMNS"] = "82"  # argparse wraps to the terminal's width, less 2
        try:
            parser = build_parser()
            out: list[nodes.Node] = [self._block(parser.format_help())]
            subs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
            summary = {a.dest: a.help for a in subs._choices_actions}
            for name, sub in subs.choices.items():
                section = nodes.section()
                section["ids"].append(nodes.make_id(f"multimass-{name}"))
                section += nodes.title(text=f"multimass {name}")
                if summary.get(name):
                    section += nodes.paragraph(
                        text=summary[name][0].upper() + summary[name][1:] + "."
                    )
                section += self._block(sub.format_help())
                self.state.document.note_implicit_target(section)
                out.append(section)
        finally:
            if previous is None:
                os.environ.pop("COLUMNS", None)
            else:
                os.environ["COLUMNS"] = previous
        self.env.note_dependency(str(ROOT / "multimass" / "cli" / "__init__.py"))
        return out

    @staticmethod
    def _block(text: str) -> nodes.literal_block:
        block = nodes.literal_block(text, text)
        block["language"] = "text"
        return block


# -- where each public name is documented ---------------------------------------------
# Every public name is documented once, in full, in the public module that defines it.
# A package that re-exports names from its submodules (`multimass`, `multimass.modal`,
# ...) lists them in a summary table that links to those definitions, so no object is
# described twice (Sphinx would warn about duplicate descriptions of re-exported classes).
# Public modules left out: the cli's sub-command modules (the command-line page shows the
# commands) and multimass.engines.fast.preload, whose import compiles the numba kernels (that is
# its purpose; up to a minute with a cold cache).
_NOT_DOCUMENTED = ("multimass.cli.", "multimass.engines.fast.preload")


def _documented(module_name: str) -> bool:
    parts = module_name.split(".")
    return (
        parts[0] == "multimass"
        and not any(p.startswith("_") for p in parts)
        and not module_name.startswith(_NOT_DOCUMENTED)
    )


def _lists(module, name: str, obj) -> bool:
    return name in (getattr(module, "__all__", None) or ()) and getattr(module, name, None) is obj


def documented_at(module_name: str, name: str) -> str:
    """Where ``module_name.name`` is documented in full: ``""`` when on its own page.

    Used by the autosummary module template (``autosummary_context``).
    """
    module = importlib.import_module(module_name)
    obj = getattr(module, name)
    home = getattr(obj, "__module__", None)
    if isinstance(home, str) and home != module_name and _documented(home):
        defining = importlib.import_module(home)
        if _lists(defining, name, obj):
            return f"{home}.{name}"
    if hasattr(module, "__path__") and not isinstance(home, str):
        # data re-exported by a package (e.g. multimass.G): the plain module that lists it
        for other in sorted(sys.modules):
            mod = sys.modules[other]
            if other == module_name or not _documented(other) or hasattr(mod, "__path__"):
                continue
            if _lists(mod, name, obj):
                return f"{other}.{name}"
    return ""


def _modules() -> tuple[list[str], list[str]]:
    """The package's documented modules (imported) and its public ones left out."""
    import multimass

    documented, left_out = ["multimass"], []
    for info in pkgutil.walk_packages(multimass.__path__, "multimass."):
        if _documented(info.name):
            importlib.import_module(info.name)
            documented.append(info.name)
        elif not any(p.startswith("_") for p in info.name.split(".")):
            left_out.append(info.name)
    return documented, left_out


def _show_value(module_name: str, name: str) -> bool:
    """Data whose value reads well as Python (short literals; not machine-dependent)."""
    text = repr(getattr(importlib.import_module(module_name), name))
    try:
        ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return False
    return len(text) <= 100 and not text.startswith(("'/", '"/'))


def _has_bases(module_name: str, name: str) -> bool:
    """A class that derives from more than `object` ("Bases: object" says nothing)."""
    obj = getattr(importlib.import_module(module_name), name)
    return isinstance(obj, type) and obj.__bases__ != (object,)


# For the autosummary module template (plain data: the context is cached with the
# environment): module -> {public name -> the module.name where it is documented in full},
# and module -> the public classes whose bases are worth showing.
_MODULES, _LEFT_OUT = _modules()
autosummary_context = {
    "left_out": _LEFT_OUT,
    "homes": {
        module: {
            name: home
            for name in getattr(importlib.import_module(module), "__all__", ())
            if (home := documented_at(module, name))
        }
        for module in _MODULES
    },
    "with_bases": {
        module: [
            name
            for name in getattr(importlib.import_module(module), "__all__", ())
            if _has_bases(module, name)
        ]
        for module in _MODULES
    },
    "with_value": {
        module: [
            name
            for name in getattr(importlib.import_module(module), "__all__", ())
            if _show_value(module, name)
        ]
        for module in _MODULES
    },
}


def _documented_name(name: str, objects) -> str:
    """The documented object that ``name`` (a full dotted name) is, or ``""``."""
    if name in objects:
        return name
    parts = name.split(".")
    for cut in range(len(parts) - 1, 0, -1):  # the longest importable module prefix
        module_name = ".".join(parts[:cut])
        if module_name not in sys.modules:
            continue
        try:
            home = documented_at(module_name, parts[cut])
        except AttributeError:
            return ""
        full = ".".join([home, *parts[cut + 1 :]]) if home else ""
        return full if full in objects else ""
    return ""


def _resolve(app, env, node, contnode):
    """``missing-reference``: resolve the docstrings' `name` references as a reader would.

    `multimass.simulate` is `multimass.simulation.simulate` (a re-export); `simulate` in
    a module of multimass.engines.nscd is `multimass.engines.nscd.simulate`, else `multimass.simulate`;
    `nscd.cost` is `multimass.engines.nscd.cost`; `Scene` or `Response.series` is the one
    documented object whose name ends so. Anything else stays plain code.
    """
    if node.get("refdomain") != "py":
        return None
    domain = env.domains["py"]
    objects = domain.objects
    target = node.get("reftarget", "")
    # a lowercase name may be a parameter's: it does not link to a module of that name
    plain = "." not in target and target[:1].islower() and target != "multimass"
    if target.startswith("multimass."):
        candidates = [target]
    else:
        parts = (node.get("py:module") or "multimass").split(".")
        candidates = [".".join([*parts[:i], target]) for i in range(len(parts), 0, -1)]
    for candidate in candidates:
        full = _documented_name(candidate, objects)
        if full and not (plain and objects[full].objtype == "module"):
            break
    else:
        full = ""
        if not plain:
            ends = [n for n, o in objects.items() if n.endswith("." + target) and not o.aliased]
            full = ends[0] if len(ends) == 1 else ""
    if not full:
        return None
    return domain.resolve_xref(
        env, node["refdoc"], app.builder, node["reftype"], full, node, contnode
    )


# -- member filtering and tolerated warnings ---------------------------------------------
def _skip_member(app, what, name, obj, skip, options):
    """Drop typing.NamedTuple's generated field docstrings ("Alias for field number 0")."""
    doc = getattr(obj, "__doc__", None) or ""
    if what == "class" and doc.startswith("Alias for field number"):
        return True
    return None


def _clean_generated(app) -> None:
    """Start from no generated pages: a module removed since the last build leaves none."""
    shutil.rmtree(HERE / "api" / "generated", ignore_errors=True)


class _TolerateModules(logging.Filter):
    """Drops the warnings located in the modules of `WARNINGS_TOLERATED_IN`.

    That is: in their docstrings, on their own generated pages, and in the summary
    tables of the pages that re-export their objects (an autosummary line quotes the
    first line of a docstring; any other module's docstring is still checked in full).
    """

    def __init__(self, modules: tuple[str, ...], pages: list[str]) -> None:
        super().__init__()
        self.where: dict[str, re.Pattern] = {}
        for m in modules:
            where = [
                rf"/{re.escape(m.replace('.', '/'))}\.py:",  # .../newmark.py:docstring of ...
                rf"/generated/{re.escape(m)}\.rst:",
            ]
            for page in pages:  # pages whose summary tables quote the module's objects
                mod = importlib.import_module(page)
                if any(
                    getattr(getattr(mod, name, None), "__module__", None) == m
                    for name in getattr(mod, "__all__", ())
                ):
                    where.append(rf"/generated/{re.escape(page)}\.rst:\d+:<autosummary>")
            self.where[m] = re.compile("|".join(where))
        self.dropped = dict.fromkeys(modules, 0)

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno < logging.WARNING:
            return True
        location = getattr(record, "location", None)
        if isinstance(location, tuple):
            location = ":".join(str(x) for x in location)
        elif isinstance(location, nodes.Node):
            location = f"{location.source}:{location.line}"
        for module, where in self.where.items():
            if where.search(f"{location or ''}:"):
                self.dropped[module] += 1
                return False
        return True

    def report(self, app, exception) -> None:
        """``build-finished``: name the modules that no longer need their tolerance."""
        if exception is not None or app.builder.name != "html":
            return
        for module, count in self.dropped.items():
            if count == 0:
                sphinx_logging.getLogger(__name__).warning(
                    "%s no longer warns: remove it from WARNINGS_TOLERATED_IN in docs/conf.py",
                    module,
                )
            else:
                sphinx_logging.getLogger(__name__).info(
                    "%d warnings tolerated in %s (WARNINGS_TOLERATED_IN)", count, module
                )


def setup(app):
    app.connect("builder-inited", _clean_generated, priority=100)  # before autosummary
    app.connect("autodoc-skip-member", _skip_member)
    app.connect("missing-reference", _resolve)
    app.add_directive("multimass-help", CommandHelp)
    if WARNINGS_TOLERATED_IN:
        tolerate = _TolerateModules(WARNINGS_TOLERATED_IN, _MODULES)
        # ahead of Sphinx's own filters on its warning handler, which count warnings
        for handler in logging.getLogger("sphinx").handlers:
            if isinstance(handler, sphinx_logging.WarningStreamHandler):
                handler.filters.insert(0, tolerate)
        app.connect("build-finished", tolerate.report)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
