"""The impact model: M, W and u⁻ (:mod:`.structure`, :mod:`.problem`), builders of
chains and random impacts (:mod:`.builders`), the admissible set S (:mod:`.admissible`)
and the geometric classification of a post-impact velocity (:mod:`.classify`)
(docs/theory.md §1, §2, §4, §5)."""
