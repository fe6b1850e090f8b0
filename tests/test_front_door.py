"""The front door: a top level of the names of daily use, public submodules for the rest, and
every name that left the top level still reachable there (with a DeprecationWarning that
names its new place) as the very same object."""

from __future__ import annotations

import importlib
import warnings

import pytest

import impactqp as iq

# names added to the top level after the public submodules came (issue 27); the
# derivatives (issue 26) count with the former ones: 107 + 3, each must still resolve
ADDED = {"compare_backends", "plot_admissible", "plot_sectors"}
FORMER_TOP_LEVEL = sorted((set(iq.__all__) | set(iq._MOVED)) - ADDED)


def test_the_top_level_is_small() -> None:
    assert len(iq.__all__) <= 55
    assert len(set(iq.__all__)) == len(iq.__all__)
    assert len(FORMER_TOP_LEVEL) == 110


def test_the_figures_are_at_the_top_level() -> None:
    from impactqp.figures import sections

    assert ADDED <= set(iq.__all__)
    assert iq.plot_admissible is sections.plot_admissible
    assert iq.plot_sectors is sections.plot_sectors


def test_dir_shows_the_top_level_and_the_submodules_only() -> None:
    assert set(dir(iq)) == set(iq.__all__) | set(iq.SUBMODULES) | {"__version__"}


@pytest.mark.parametrize("sub", iq.SUBMODULES)
def test_every_submodule_name_resolves(sub: str) -> None:
    module = importlib.import_module(f"impactqp.{sub}")
    assert getattr(iq, sub) is module
    assert module.__all__ and len(set(module.__all__)) == len(module.__all__)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing a submodule exports is deprecated
        for name in module.__all__:
            assert getattr(module, name) is not None, (sub, name)


def test_a_top_level_name_is_the_same_object_in_its_submodule() -> None:
    for sub in iq.SUBMODULES:
        module = importlib.import_module(f"impactqp.{sub}")
        for name in set(module.__all__) & set(iq.__all__):
            assert getattr(module, name) is getattr(iq, name), (sub, name)


def test_every_moved_name_is_in_the_submodule_it_names() -> None:
    for name, sub in iq._MOVED.items():
        assert name not in iq.__all__
        assert name in importlib.import_module(f"impactqp.{sub}").__all__, (name, sub)


@pytest.mark.parametrize("name", sorted(iq._MOVED))
def test_a_moved_name_still_resolves_with_a_warning(name: str) -> None:
    sub = iq._MOVED[name]
    with pytest.warns(DeprecationWarning, match=rf"iq\.{name} moved to impactqp\.{sub}\.{name}"):
        old = getattr(iq, name)
    assert old is getattr(importlib.import_module(f"impactqp.{sub}"), name)


def test_the_top_level_names_resolve_without_a_warning() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in FORMER_TOP_LEVEL:
            if name in iq.__all__:
                getattr(iq, name)
        from impactqp import SectorLaw, simulate  # noqa: F401


def test_from_import_of_a_moved_name_warns_too() -> None:
    with pytest.warns(DeprecationWarning, match="impactqp.tables.SectorTable"):
        from impactqp import SectorTable
    assert SectorTable is iq.tables.SectorTable


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no_such_name"):
        iq.no_such_name  # noqa: B018
    assert not hasattr(iq, "SectorTables")


def test_a_name_off_the_top_level_has_one_home() -> None:
    homes: dict[str, list[str]] = {}
    for sub in iq.SUBMODULES:
        for name in importlib.import_module(f"impactqp.{sub}").__all__:
            if name not in iq.__all__:
                homes.setdefault(name, []).append(sub)
    assert {n: subs for n, subs in homes.items() if len(subs) > 1} == {}
    # every name of the former top level has a place: the top level or its one submodule
    assert {n for n in FORMER_TOP_LEVEL if n not in iq.__all__} <= set(homes)
