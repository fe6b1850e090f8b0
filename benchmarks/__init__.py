"""Benchmark suite of impactqp: ``python -m benchmarks run --suite quick|full|friction
[--out DIR] [--merge]``.

Families of seeded impact problems (:mod:`.families`), the timed methods (:mod:`.methods`),
timing and accuracy (:mod:`.measure`), the Siconos peer in Debian's Python (:mod:`.peers`,
:mod:`.siconos_worker`), whole runs — simulations beside Siconos' MoreauJeanOSI
(:mod:`.simulation`), per-impact timings and the first calls of a fresh process
(:mod:`.dynamics`, :mod:`.startup`) — the friction suite (FCLib problems beside Siconos'
fc3d solvers, :mod:`.friction`, :mod:`.friction_data`; frictional impacts of spheres,
:mod:`.friction_impacts`; its table, targets and Dolan–Moré profile,
:mod:`.friction_report`, :mod:`.perf_profile`), the driver (:mod:`.runner`) and the
reports (:mod:`.report`).
"""

import os

# Benchmarks time machine code: no call of theirs runs a kernel's Python text, as a small first
# call of a cold process otherwise would (impactqp/kernels/first_calls.py). The first-hour
# probes of :mod:`.startup` set the variable themselves.
os.environ.setdefault("IMPACTQP_INTERPRETED_SECONDS", "0")
