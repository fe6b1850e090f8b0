"""Command-line entry point ``impactqp``: each subcommand lives in :mod:`impactqp.cli.commands`."""

from __future__ import annotations

import argparse
import os
import sys
from importlib.metadata import PackageNotFoundError, version

from ..base.log import verbosity
from ..errors import ImpactError, OutOfRangeError
from .commands import (
    backends,
    bench,
    compile,
    demo,
    fclib,
    plot,
    sector,
    simulate,
    solve,
    verify,
)

COMMANDS = [demo, solve, verify, fclib, plot, sector, simulate, compile, bench, backends]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="impactqp", allow_abbrev=False,
                                     description="Rigid-body impacts as convex programs.")
    try:
        installed = version("impactqp")
    except PackageNotFoundError:
        installed = "0+unknown"
    parser.add_argument("--version", action="version", version=f"impactqp {installed}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log refusals and fallbacks on stderr (-vv: every backend "
                             "attempt and certificate)")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    return parser


NUMBER_OPTIONS = ("--u-plus", "--eps", "--e", "--E", "--mu", "--v", "--mass", "--stiffness",
                  "--exponent")
"""Options whose value may start with a minus sign (``--u-plus -1,0,0``)."""


def join_negative_values(argv: list[str]) -> list[str]:
    """``--u-plus -1,0,0`` as ``--u-plus=-1,0,0``: argparse would read the value as an option."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        token = argv[i]
        if token in NUMBER_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-") \
                and len(argv[i + 1]) > 1 and (argv[i + 1][1].isdigit() or argv[i + 1][1] == "."):
            out.append(f"{token}={argv[i + 1]}")
            i += 2
            continue
        out.append(token)
        i += 1
    return out


def _fail(message: str) -> int:
    text = " ".join(str(message).split()) or "unknown failure"
    print(f"impactqp: error: {text}", file=sys.stderr)
    return 2


def _closed_output() -> int:
    """The reader of our output went away (``impactqp ... | head``): end quietly, as Unix
    tools do. Output still buffered would fail again when the interpreter flushes it at exit,
    so stdout is pointed at the null device first."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout without a file descriptor (captured in tests)
        pass
    return 0


def out_of_range(command: str, exc: OverflowError) -> OutOfRangeError:
    """The named error of a number that left the float range while ``command`` ran."""
    cause = exc.args[-1] if exc.args else type(exc).__name__
    return OutOfRangeError(f"{command}: a number left the range of floats (magnitudes up to "
                           f"{sys.float_info.max:.3g}; {cause}); impacts do not depend on "
                           "the units (docs/theory.md §8): give the input in units that "
                           "keep its numbers and their squares finite")


def main(argv: list[str] | None = None) -> int:
    """Run the ``impactqp`` command; return its exit status.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The command's own status (``verify``: 0 admissible, 1 not), 2 for any failure:
        bad input, unreadable or hostile files, unwritable outputs, solver failures. A
        failure is one line on stderr, never a traceback (set IMPACTQP_DEBUG=1 to see one).
        Output into a pipe closed by its reader (``| head``) ends the command quietly with 0.
    """
    argv = join_negative_values(list(sys.argv[1:] if argv is None else argv))
    args = build_parser().parse_args(argv)
    try:
        with verbosity(min(args.verbose, 2)):
            status = int(args.func(args))
            sys.stdout.flush()  # a closed pipe shows here, not at the interpreter's exit
            return status
    except BrokenPipeError:
        return _closed_output()
    except ImpactError as exc:
        return _fail(str(exc))
    except OSError as exc:  # unwritable --out, vanished files
        where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        return _fail(f"cannot access{where}: {exc.strerror or exc}")
    except OverflowError as exc:
        if os.environ.get("IMPACTQP_DEBUG"):
            raise
        return _fail(str(out_of_range(args.command, exc)))
    except (MemoryError, RecursionError, ValueError) as exc:
        if os.environ.get("IMPACTQP_DEBUG"):
            raise
        return _fail(f"{type(exc).__name__}: {exc}")
    except KeyboardInterrupt:
        print("impactqp: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
