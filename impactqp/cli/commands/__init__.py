"""Subcommands of the ``impactqp`` command line, one module each with ``register(subparsers)``."""
