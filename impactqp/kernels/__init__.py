"""Compiled kernels: the one definition of each small, hot computation (docs/theory.md §9).

Every function here is compiled by numba on its first call (cached on disk, never at
import) and runs as plain Python under ``NUMBA_DISABLE_JIT=1``. The layer sits above
:mod:`impactqp.base` and below :mod:`impactqp.qp`: kernels take and return arrays and
floats, never problems, laws or programs.
"""
