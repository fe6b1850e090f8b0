"""Sphinx configuration of impactqp's documentation.

Build with ``sphinx-build -W --keep-going -b html docs docs/_build/html`` after
``pip install -e ".[docs]"``. The API reference is generated from the numpydoc docstrings of
the public names (``impactqp.__all__``); the theory note docs/theory.md is read by myst-parser.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # document the source tree, installed or not

import impactqp  # noqa: E402

project = "impactqp"
author = "the impactqp authors"
copyright = "2026, the impactqp authors"
release = impactqp.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

# autodoc / autosummary: the API page lists everything itself, no stub files are generated
autosummary_generate = False
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections carry the types
autodoc_preserve_defaults = True

# numpydoc: class members are documented by autodoc, not listed again by numpydoc
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# myst-parser: the theory note is plain Markdown with tables
myst_heading_anchors = 3

html_theme = "alabaster"
html_title = f"impactqp {release}"
html_static_path: list[str] = []
