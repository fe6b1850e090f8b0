"""Links to Python, NumPy, SciPy and matplotlib that degrade to plain names offline.

docs/conf.py lists each project's online inventory first and ``_ext/offline.inv`` (an empty
inventory) second: online, Sphinx reads the real one and links every name of those projects;
offline (CI reaches package registries only), the fetch fails, the empty one is read, and
Sphinx merely notes it instead of warning, so a nitpicky build with warnings as errors still
passes. A reference into a project whose inventory is empty is then shown as its name
without a link (:func:`unlinked_offline`), but only if the name exists: an importable
``numpy.ndarray``, a builtin ``float``, or a ``python:``/``numpy:`` target of numpydoc's
type links; anything else still fails the build.
"""

from __future__ import annotations

import builtins
import sys

from docutils import nodes
from dotted_names import exists
from sphinx.ext.intersphinx import InventoryAdapter

# the top-level modules each inventory documents
MODULES = {"python": None, "numpy": "numpy", "scipy": "scipy", "matplotlib": "matplotlib"}


def _offline(env) -> set[str]:
    """The inventories of docs/conf.py that were read empty (their site was unreachable)."""
    named = InventoryAdapter(env).named_inventory
    return {name for name in MODULES if not any(named.get(name, {}).values())}


def unlinked_offline(app, env, node, contnode):
    """``missing-reference`` (after intersphinx): the name of an existing object of a
    project whose inventory could not be fetched, without a link."""
    offline = _offline(env)
    if not offline:
        return None
    target = node.get("reftarget", "")
    project, _, rest = target.partition(":")
    if rest and project in offline:  # an explicit inventory, as numpydoc writes python:list
        return _without_prefix(contnode, f"{project}:")
    if node.get("refdomain") != "py":
        return None
    target = target.lstrip("~.")
    top = target.split(".")[0]
    if top in {MODULES[p] for p in offline} and exists(target):
        return contnode
    if "python" in offline and "." not in target and hasattr(builtins, target):
        return contnode
    if "python" in offline and top in sys.stdlib_module_names and exists(target):
        return contnode  # the standard library: pathlib.Path
    return None


def _without_prefix(contnode, prefix: str):
    """The reference's text without the inventory's name, as intersphinx shows it."""
    text = contnode.astext()
    if not text.startswith(prefix):
        return contnode
    shown = contnode.deepcopy()
    shown.children = [nodes.Text(text[len(prefix):])]
    return shown


def setup(app):
    app.connect("missing-reference", unlinked_offline, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
