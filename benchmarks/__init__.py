"""Benchmark suite of impactqp: ``python -m benchmarks run --suite quick|full [--out DIR]``.

Families of seeded impact problems (:mod:`.families`), the timed methods (:mod:`.methods`),
timing and accuracy (:mod:`.measure`), the Siconos peer in Debian's Python (:mod:`.peers`,
:mod:`.siconos_worker`), the driver (:mod:`.runner`) and the reports (:mod:`.report`).
"""
