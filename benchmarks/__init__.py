"""Benchmark suite of impactqp: ``python -m benchmarks run --suite quick|full [--out DIR]``.

Families of seeded impact problems (:mod:`.families`), the timed methods (:mod:`.methods`),
timing and accuracy (:mod:`.measure`), the Siconos peer in Debian's Python (:mod:`.peers`,
:mod:`.siconos_worker`), whole runs — simulations beside Siconos' MoreauJeanOSI
(:mod:`.simulation`), per-impact timings and the first calls of a fresh process
(:mod:`.dynamics`, :mod:`.startup`) — the driver (:mod:`.runner`) and the reports
(:mod:`.report`).
"""
