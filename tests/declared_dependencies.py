"""The distributions pyproject.toml declares, by name: the core install's and each extra's
(tests/test_compare_backends.py, tests/test_fclib_extra.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

PYPROJECT = Path(__file__).resolve().parent.parent / "pyproject.toml"


def _name(requirement: str) -> str:
    """The distribution a requirement names (``"h5py>=3.8"`` → ``"h5py"``)."""
    return requirement.split(">")[0].split(";")[0].strip()


def declared() -> tuple[set[str], dict[str, set[str]]]:
    """(core, extras): the names of the core dependencies, and those of each extra."""
    tomllib = pytest.importorskip("tomllib")
    project = tomllib.loads(PYPROJECT.read_text())["project"]
    core = {_name(d) for d in project["dependencies"]}
    extras = {k: {_name(d) for d in v} for k, v in project["optional-dependencies"].items()}
    return core, extras
