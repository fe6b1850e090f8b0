"""Piecewise-linear laws as tables, certified exactly: the sector law's n! cones
(:mod:`.sector_table`), the reflection law's table (:mod:`.reflection_table`), their
certificate (:mod:`.certificate`) and the mass ratios where the sector law is continuous
(:mod:`.coxeter`) (docs/theory.md §7, §11).

This package is public: ``impactqp.tables`` re-exports the names below."""

from .certificate import SectorCertificate, TableCertificate
from .coxeter import continuous_mass_ratios
from .reflection_table import reflection_law_table
from .sector_table import SectorCone, SectorTable, sector_law_table

__all__ = [
    "sector_law_table", "SectorTable", "SectorCone", "TableCertificate", "SectorCertificate",
    "reflection_law_table", "continuous_mass_ratios",
]
