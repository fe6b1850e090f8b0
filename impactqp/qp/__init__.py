"""The solver layer: backend-neutral convex programs and everything that solves them.

Programs (:mod:`.program`), the backend registry with one module per solver
(:mod:`.backends`), active-set polishing (:mod:`.polish`), the certified solve loop
(:mod:`.certified`) and symmetric LCPs (:mod:`.lcp`). Nothing here knows about impacts:
laws hand programs down and take solutions back (docs/theory.md §9).
"""
