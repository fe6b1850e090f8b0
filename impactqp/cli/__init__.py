"""The command line: ``impactqp demo|solve|verify|sector-law|plot`` (entry point :func:`main`)."""

from .main import main

__all__ = ["main"]
