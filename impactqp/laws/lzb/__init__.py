"""The LZB model of Liu, Zhao and Brogliato as an impact law (docs/theory.md §13): the law
(:mod:`.law`), its dimensionless dynamics (:mod:`.dynamics`), the integration driving the
compiled stepper of :mod:`impactqp.kernels.lzb` or scipy's reference (:mod:`.integration`)
and its certificate (:mod:`.certificate`)."""

from .certificate import LZBCertificate, lzb_certificate, lzb_residuals
from .dynamics import LZBDynamics, Scales, log_force_coefficient
from .integration import LZBRecord, integrate
from .law import DEFAULT_RTOL, ENERGY_TARGET, LZB, MIN_RTOL, LZBAnswer

__all__ = ["DEFAULT_RTOL", "ENERGY_TARGET", "LZB", "MIN_RTOL", "LZBAnswer", "LZBCertificate",
           "LZBDynamics", "LZBRecord", "Scales", "integrate", "log_force_coefficient",
           "lzb_certificate", "lzb_residuals"]
