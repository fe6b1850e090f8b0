"""Bottom layer: input conversion, row-wise reductions and the shared verdict of certificates.

Nothing here knows about impacts; every other layer may import it.
"""
