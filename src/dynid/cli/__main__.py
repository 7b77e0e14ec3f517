"""dynid: kinematics, dynamics and dynamic identification of robot manipulators.

Run ``dynid <command> --help`` for the options of one command.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from ..exceptions import DynidError

#: Subcommands in pipeline order; each is the module ``dynid.cli.<module>`` with
#: ``NAME``, ``register(subparsers)`` and ``run(args) -> int``.
SUBCOMMANDS = (
    "fk",
    "jacobian",
    "ik",
    "import_bag",
    "acquire_static",
    "identify",
    "predict",
    "simulate",
    "friction",
    "validate",
    "retrieve",
    "payload",
    "export",
    "demo",
)


def _modules():
    for name in SUBCOMMANDS:
        try:
            yield importlib.import_module(f"{__package__}.{name}")
        except ModuleNotFoundError as exc:  # a subcommand not built yet
            if exc.name != f"{__package__}.{name}":
                raise


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="dynid", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"dynid {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for mod in _modules():
        p = mod.register(sub)
        p.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
        p.add_argument("-q", "--quiet", action="store_true", help="errors only")
        p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``dynid`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    level = (
        logging.ERROR
        if args.quiet
        else (
            logging.DEBUG if args.verbose > 1 else logging.INFO if args.verbose else logging.WARNING
        )
    )
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    try:
        return int(args._run(args) or 0)
    except (DynidError, OSError) as exc:
        if args.debug:
            raise
        print(f"dynid {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
