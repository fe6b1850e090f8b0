import os
import sys
from pathlib import Path

from hypothesis import settings

sys.path.insert(0, str(Path(__file__).parent))

# CI runs the same examples every time (a red CI must be reproducible); locally hypothesis
# explores new ones. HYPOTHESIS_PROFILE=deep runs many more.
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("deep", max_examples=600, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else
                                     "default"))


FIRST = ("tests/test_compile_ahead.py::"
         "test_compile_fills_the_cache_and_later_processes_compile_nothing")
"""Runs before every other test: it compiles every kernel into an empty cache, and hands that
machine code to the session's own cache (so the rest of the suite compiles little)."""


def pytest_collection_modifyitems(items):
    items.sort(key=lambda item: item.nodeid != FIRST)  # stable: the rest keep their order
