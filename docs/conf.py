"""Sphinx configuration of impactqp's documentation.

Build with ``sphinx-build -n -W --keep-going -b html docs docs/_build/html`` after
``pip install -e ".[docs]"`` (nitpicky, as CI does: every cross-reference must resolve).
The API reference is generated from the numpydoc docstrings of the public names
(``impactqp.__all__`` and the ``__all__`` of each public submodule), their citations
"docs/theory.md §N" linked to the sections of the theory note (``_ext/theory_links.py``);
the theory note docs/theory.md is read by myst-parser, its formulas rendered by MathJax; the
gallery is generated from ``examples/`` by sphinx-gallery, which runs the scripts and shows
what they print and draw (``_ext/gallery_files.py``); names of Python, NumPy, SciPy and
matplotlib link to their documentation when it is reachable (``_ext/offline_intersphinx.py``);
the command line's help texts are printed by its own parser (the ``impactqp-help`` directive
below). Everything it needs is in the ``docs`` extra of pyproject.toml.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # document the source tree, installed or not
sys.path.insert(0, str(ROOT / "docs" / "_ext"))  # this site's own extensions

from offline_intersphinx import exists  # noqa: E402

import impactqp  # noqa: E402

project = "impactqp"
author = "the impactqp authors"
copyright = "2026, the impactqp authors"
release = impactqp.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinx_copybutton",
    "theory_links",
    "offline_intersphinx",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store"]

# autodoc / autosummary: the API page lists everything itself, no stub files are generated
autosummary_generate = False
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections carry the types
autodoc_preserve_defaults = True

# numpydoc: class members are documented by autodoc, not listed again by numpydoc
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = True  # the types of Parameters/Returns link where they can
numpydoc_xref_ignore = "all"  # only the names below and numpydoc's own (int, ndarray, ...)
numpydoc_xref_aliases = {
    "Path": "pathlib.Path",
    "Figure": "matplotlib.figure.Figure",
    "Axes": "matplotlib.axes.Axes",
    "matplotlib.axes.Axes": "matplotlib.axes.Axes",
    "sparse": "scipy.sparse",
    "csr_matrix": "scipy.sparse.csr_matrix",
    "csc_matrix": "scipy.sparse.csc_matrix",
    "LinearOperator": "scipy.sparse.linalg.LinearOperator",
    "Generator": "numpy.random.Generator",
    "callable": ":term:`python:callable`",  # the glossary's entry, not "callable()"
}

# myst-parser: the theory note is Markdown with tables and LaTeX formulas ($…$, $$…$$ and
# amsmath environments), rendered by MathJax; its numbered sections are anchored sec-N
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath", "amsmath"]

# intersphinx: each project's inventory online, else an empty one (_ext/offline_intersphinx.py)
OFFLINE = "_ext/offline.inv"
intersphinx_mapping = {
    "python": ("https://docs.python.org/3", (None, OFFLINE)),
    "numpy": ("https://numpy.org/doc/stable", (None, OFFLINE)),
    "scipy": ("https://docs.scipy.org/doc/scipy", (None, OFFLINE)),
    "matplotlib": ("https://matplotlib.org/stable", (None, OFFLINE)),
}
intersphinx_timeout = 10

# sphinx-gallery: every script of examples/ is a page (its docstring's title and text, its
# code, downloadable as .py and .ipynb); the scripts matching filename_pattern are run at
# build time, with what they print and the figures they write (thumbnails from the first).
# benchmark_run.py is shown but not run: it runs a benchmark suite (about a minute).
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/(?!benchmark_run\.py$)[^/]+\.py$",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib", "gallery_files.scrape_written_files"),
    "reset_modules": ("matplotlib", "gallery_files.private_tempdir"),
    "reset_modules_order": "both",
    "reset_argv": "gallery_files.run_as_script",
    "download_all_examples": True,
    "write_computation_times": False,
    "remove_config_comments": True,
    "show_memory": False,
    "abort_on_example_error": True,
}

# sphinx-copybutton: copy a block's code without its prompts and output
copybutton_prompt_text = r">>> |\.\.\. |\$ "
copybutton_prompt_is_regexp = True

html_theme = "pydata_sphinx_theme"
html_title = f"impactqp {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "header_links_before_dropdown": 4,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc", "sourcelink"],
}
# the left column lists a section's pages: only the gallery has any, the other pages (the
# theory note's formulas above all) take its width
html_sidebars = {"*": [], "auto_examples/*": ["sidebar-nav-bs"]}
html_show_sourcelink = True


def _help_text(path: str) -> str:
    """The ``--help`` text of ``impactqp`` (``path`` empty) or of a subcommand such as
    ``"solve"`` or ``"plot S"``, exactly as the parser of impactqp.cli prints it."""
    import argparse

    from impactqp.cli.main import build_parser

    os.environ["COLUMNS"] = "88"  # argparse wraps to the terminal; the page has a fixed width
    parser = build_parser()
    for name in path.split():
        subparsers = next(a for a in parser._actions
                          if isinstance(a, argparse._SubParsersAction))
        parser = subparsers.choices[name]
    return parser.format_help()


PUBLIC_MODULES = ("impactqp", *(f"impactqp.{sub}" for sub in impactqp.SUBMODULES))


def _public_classes() -> dict[str, str]:
    """Name → path of every public class (the top level's first), so that a class named as
    a parameter's or a result's type links to its entry."""
    import importlib

    found: dict[str, str] = {}
    for module in PUBLIC_MODULES:
        namespace = importlib.import_module(module)
        for name in namespace.__all__:
            if isinstance(getattr(namespace, name), type):
                found.setdefault(name, f"{module}.{name}")
    return found


numpydoc_xref_aliases.update(_public_classes())


def _public_reference(app, env, node, contnode):
    """A bare name in a docstring (``:class:`ImpactResult```) rendered in another public
    module's section, or an implementation path of a public object, resolves to the public
    object of that name, at the top level or in the submodule that documents it; a full path
    of an internal object that exists is shown as its name without a link (tests/test_docs.py
    checks that every such path names an existing object); anything else still fails."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    domain = env.get_domain("py")
    candidates = [target]
    if target.startswith("impactqp."):  # an implementation path: its public name, if any
        candidates.append(target.rsplit(".", 1)[1])
    for module, short in ((m, c) for c in candidates for m in PUBLIC_MODULES):
        name = f"{module}.{short}"
        if name in domain.objects:
            return domain.resolve_xref(env, node["refdoc"], app.builder, node["reftype"], name,
                                       node, contnode)
    if target.startswith("impactqp.") and exists(target):
        return contnode  # an internal object the page does not document: its name, unlinked
    return None


def setup(app):
    """``.. impactqp-help:: [SUBCOMMAND ...]`` renders the command line's own help text, so
    the command-line page cannot drift from the parser; bare names resolve across the public
    modules (:func:`_public_reference`)."""
    from docutils import nodes
    from sphinx.util.docutils import SphinxDirective

    class ImpactqpHelp(SphinxDirective):
        optional_arguments = 1
        final_argument_whitespace = True

        def run(self) -> list:
            text = _help_text(self.arguments[0] if self.arguments else "")
            block = nodes.literal_block(text, text)
            block["language"] = "text"
            return [block]

    app.add_directive("impactqp-help", ImpactqpHelp)
    app.connect("missing-reference", _public_reference)
    return {"parallel_read_safe": True}
