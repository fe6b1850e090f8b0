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
