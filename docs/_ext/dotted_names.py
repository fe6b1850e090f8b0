"""Whether a dotted name names an object: what the offline links of
``offline_intersphinx.py`` and the docstring cross-reference check of tests/test_docs.py both
ask (no Sphinx needed here)."""

from __future__ import annotations

import builtins
import importlib


def exists(dotted: str, *, builtin: bool = True) -> bool:
    """Does ``a.b.c`` name an importable module or an attribute chain below one (or, with
    ``builtin``, a builtin such as ``ValueError``)?"""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return builtin and hasattr(builtins, dotted)
