"""Every public name has a numpydoc docstring with the sections it needs, and the API page
of the documentation lists every public name."""

from __future__ import annotations

import inspect
import re
import warnings
from pathlib import Path

import pytest

import impactqp as iq

API = Path(__file__).resolve().parents[1] / "docs" / "api.rst"

def _names(entries: list) -> set[str]:
    """Documented names; ``a, b : float`` documents both a and b."""
    return {part.strip() for entry in entries for part in entry.name.split(",")}


def _arguments(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name != "self"
            and not p.name.startswith("_")]


def problems(name: str) -> list[str]:
    """What the docstring of ``iq.<name>`` lacks."""
    from numpydoc import docscrape  # in the test extra
    obj = getattr(iq, name)
    if not inspect.getdoc(obj):
        return ["no docstring"]
    if inspect.isclass(obj) and issubclass(obj, BaseException):
        return []  # an exception takes its message; its docstring says when it is raised
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpydoc warns on unknown sections
        if inspect.isclass(obj):
            doc = docscrape.ClassDoc(obj, config={"show_class_members": False})
        else:
            doc = docscrape.FunctionDoc(obj)
    found = []
    arguments = _arguments(obj)
    documented = _names(doc["Parameters"]) | (_names(doc["Attributes"])
                                              if inspect.isclass(obj) else set())
    missing = [a for a in arguments if a not in documented]
    if missing:
        found.append(f"arguments without a Parameters (or Attributes) entry: {missing}")
    if not inspect.isclass(obj):
        returns = inspect.signature(obj).return_annotation
        if returns not in (None, "None") and not (doc["Returns"] or doc["Yields"]):
            found.append("no Returns section")
    return found


DOCUMENTED = [n for n in iq.__all__ if callable(getattr(iq, n))]


@pytest.mark.parametrize("name", DOCUMENTED)
def test_public_docstring_has_its_sections(name: str) -> None:
    assert problems(name) == [], name


def test_api_page_lists_every_public_name() -> None:
    text = API.read_text(encoding="utf-8")
    listed = set(re.findall(r"^\.\. (?:autoclass|autofunction|data):: (\w+)$", text, flags=re.M))
    assert listed == set(iq.__all__)
    assert f":value: {iq.DEFAULT_TOL!r}" in text
