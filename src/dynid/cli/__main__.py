"""dynid: kinematics, dynamics and dynamic identification of robot manipulators.

Run ``dynid <command> --help`` for the options of one command.

Exit status: 0 success; 1 a command's documented negative result, its files written
(retrieve: no feasible set; excite: no admissible trajectory; validate: a model that
does not explain the log); 2 an error (one line on
stderr; --debug shows the traceback); 130 interrupted (Ctrl-C); 129, 131, 143
terminated by SIGHUP, SIGQUIT, SIGTERM; 141 stdout was closed
before everything was printed (`dynid fk ... | head -1`: the run completes quietly, its
files are written). A failed or interrupted command leaves no file or folder of its own
behind, and no file is ever half written.

Output folders: a command writes its files into a hidden staging folder beside --out and
moves the complete set into place when it succeeds; a rerun of the same command replaces
the previous set as a whole (its files that the new run does not write are removed). A
folder holding another command's outputs, a file no dynid run wrote, or a read-only file
is not replaced without --force. Concurrent runs into one folder never mix their files.
A command that writes a folder also writes report.html there: one page with the run's
inputs, results, figures, warnings and notes.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import logging
import os
import re
import signal
import sys
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from .. import __version__
from ..exceptions import DynidError, OptionError
from ..progress import NOTE

if TYPE_CHECKING:
    from ..outputs.run_output import RunOutput
    from .console import Console

# This module imports the standard library alone at its top (and the package's light
# ``dynid/__init__``): the library and numpy are imported inside :func:`main`, whose
# Ctrl-C handling covers them (an interrupt during the imports, the first seconds of a
# run on a loaded machine, is one line and exit 130, not a traceback).

#: Longest error line printed [characters]: a message echoing megabytes of input keeps
#: its start and its end (the hint).
ERROR_LINE_LIMIT = 1000

#: Subcommands in pipeline order; each is the module ``dynid.cli.<module>`` with
#: ``NAME``, ``register(subparsers)`` and ``run(args, console) -> int``.
SUBCOMMANDS = (
    "fk",
    "jacobian",
    "ik",
    "import_bag",
    "acquire_static",
    "identify",
    "predict",
    "excite",
    "simulate",
    "friction",
    "validate",
    "observe",
    "retrieve",
    "payload",
    "export",
    "demo",
)


def _modules(names: Sequence[str] = SUBCOMMANDS):
    for name in names:
        yield importlib.import_module(f"{__package__}.{name}")


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (usage only with --help)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _command(argv: Sequence[str]) -> str | None:
    """The subcommand module named by the first non-option argument, if it names one."""
    first = next((a for a in argv if not a.startswith("-")), None)
    name = None if first is None else first.replace("-", "_")
    return name if name in SUBCOMMANDS else None


def build_parser(commands: Sequence[str] = SUBCOMMANDS) -> argparse.ArgumentParser:
    """The argument parser with the subcommands ``commands`` (default: all of them).

    :func:`main` registers only the subcommand being run, so that a call imports only
    the library modules it uses (start-up time); ``dynid --help`` lists them all.
    """
    parser = _Parser(
        prog="dynid", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--version", action="version", version=f"dynid {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for mod in _modules(commands):
        p = mod.register(sub)
        p.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
        p.add_argument("-q", "--quiet", action="store_true", help="errors only")
        p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
        output = getattr(mod, "OUTPUT", None)
        if output is not None:
            p.add_argument(
                "--force",
                action="store_true",
                help="replace read-only files, files of another command's outputs and files "
                "no dynid run wrote in --out",
            )
        p.set_defaults(
            _run=mod.run,
            _output=output,
            _report=getattr(mod, "REPORT", True),
            _applies=getattr(mod, "APPLIES", ()),
        )
    return parser


#: A value that starts like a negative number (``-0.1,0.2``, ``-.5``, ``-1e-3``), which
#: argparse would take for an option when it holds a comma.
_NEGATIVE = re.compile(r"-(\d|\.\d)")


def join_negative_values(argv: Sequence[str]) -> list[str]:
    """``--opt -0.1,0.2`` -> ``--opt=-0.1,0.2``, so that negative lists parse as values."""
    out: list[str] = []
    it = iter(range(len(argv)))
    for i in it:
        a = argv[i]
        if (
            a.startswith("--")
            and "=" not in a
            and i + 1 < len(argv)
            and _NEGATIVE.match(argv[i + 1])
        ):
            out.append(f"{a}={argv[i + 1]}")
            next(it, None)
        else:
            out.append(a)
    return out


#: Exit status when stdout was closed by its reader (128 + SIGPIPE, as a shell reports a
#: writer that SIGPIPE stopped).
STDOUT_CLOSED = 141
#: Signals that stop a run as termination (exit 128 + the signal's number).
TERMINATING = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP", "SIGQUIT") if hasattr(signal, name)
)


class Terminated(BaseException):
    """Raised in the main thread when a termination signal (SIGTERM, SIGHUP, SIGQUIT)
    arrives; ``args[0]`` is the signal's number."""


#: The termination signals received by the current run: a :class:`Terminated` raised
#: while Python runs a callback from C code (numba writing its cache through ctypes) is
#: printed and dropped, and the run went on to write its outputs and exit 0.
_RECEIVED: list[int] = []


def _terminate(signum: int, frame: object) -> None:
    _RECEIVED.append(signum)
    raise Terminated(signum)


def _raise_if_terminated() -> None:
    """Raise the :class:`Terminated` of a termination signal whose exception was dropped
    (see :data:`_RECEIVED`), before the run's outputs move into place."""
    if _RECEIVED:
        raise Terminated(_RECEIVED[0])


@contextlib.contextmanager
def _signals_and_warnings(console: Console) -> Iterator[None]:
    """SIGTERM, SIGHUP and SIGQUIT raise :class:`Terminated`; warnings go to
    :meth:`Console.warn` (one line, no source line; kept for the run's report with -q),
    each text once per run (a URDF read as the robot and again as ``--prior`` warned of
    the same inconsistent inertial twice)."""
    old = {}
    _RECEIVED.clear()  # (a signal of an earlier run in this process is not this run's)
    with contextlib.suppress(ValueError):  # not the main thread: leave signals alone
        for sig in TERMINATING:
            old[sig] = signal.signal(sig, _terminate)

    shown: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001
        from .common import cli_text

        text = cli_text(str(message))  # its Python options named by their flags
        if text not in shown:
            shown.add(text)
            console.warn(text)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = show
            yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


def _printable_streams() -> None:
    """Under an ASCII locale (``LANG=C`` without UTF-8 mode) print names that the terminal
    cannot show as ``\\xe9`` escapes instead of failing on them."""
    for stream in (sys.stdout, sys.stderr):
        if not isinstance(stream, io.TextIOWrapper):  # captured, redirected to a StringIO
            continue
        try:
            "\u00e9\u2014".encode(stream.encoding)
        except (UnicodeEncodeError, LookupError):
            stream.reconfigure(errors="backslashreplace")


#: Options whose values may name files: they keep the form the locale gave them, which the
#: file system needs (``--columns`` names a file only when it ends in ``.toml``).
FILE_OPTIONS = frozenset({"robot", "params", "prior", "trajectory", "columns"})
_SURROGATE = re.compile("[\udc80-\udcff]")


def decode_text_options(args: argparse.Namespace) -> None:
    """Decode, as UTF-8, the text options whose non-ASCII bytes the locale could not decode.

    Under an ASCII locale without UTF-8 mode (``LC_ALL=C PYTHONUTF8=0``) the interpreter
    gives each such byte as a surrogate escape (``w\\udcc3\\udcbcrfel``): a frame, link,
    joint or column name would not be the name the robot or the file holds (read as UTF-8).
    Names are decoded in place (a repeated option's every value too), so that they mean the
    same under every locale; values that may name files (:data:`FILE_OPTIONS`, and every
    ``Path``) keep the escaped form, which opens the file, and are decoded where they are
    shown or stored (:func:`dynid._checks.text`: the console, JSON files, a prior's name,
    a log's label in figures).
    """
    for dest, value in vars(args).items():
        if isinstance(value, list) and all(isinstance(v, str) for v in value):
            if dest not in FILE_OPTIONS:  # a repeated option (--contact NAME:...)
                setattr(args, dest, [_decoded(v) for v in value])
            continue
        if not isinstance(value, str) or not _SURROGATE.search(value):
            continue
        if dest in FILE_OPTIONS and (dest != "columns" or value.lower().endswith(".toml")):
            continue
        setattr(args, dest, _decoded(value))


def _decoded(value: str) -> str:
    """``value`` with its surrogate escapes decoded as the UTF-8 bytes they stand for."""
    if not _SURROGATE.search(value):
        return value
    return os.fsencode(value).decode("utf-8", "surrogateescape")


@contextlib.contextmanager
def _output_set(args: argparse.Namespace, argv: Sequence[str]) -> Iterator[RunOutput | None]:
    """The run's output set under ``--out`` (:func:`dynid.outputs.run_output.run_output`)."""
    from ..outputs.run_output import run_output

    kind, out = getattr(args, "_output", None), getattr(args, "out", None)
    if kind is None or out is None:
        yield None
        return
    if callable(kind):  # a command whose --out is a file or a folder by its inputs
        kind = kind(args)
    with run_output(
        out, command=args.command, kind=kind, force=args.force, argv=["dynid", *argv]
    ) as run:
        yield run


#: The BLAS libraries' thread counts a command sets when neither the environment nor an
#: earlier import of numpy did: one thread. The fits are tall products and QR factors of
#: a hundred columns, where a second BLAS thread gains little and, on a machine whose cores
#: are busy, spins against the other work (an exact 186,000-row log of a UR5: 31 s with one
#: thread, 64 s to 217 s with two on two shared cores; a 10 s Panda log 4 s against 33 s).
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _one_blas_thread() -> None:
    """One BLAS thread (:data:`BLAS_THREAD_VARIABLES`) unless set in the environment; only
    before numpy is loaded, which reads them once (a command called in a process that
    loaded it keeps that process's threads)."""
    if "numpy" in sys.modules:
        return
    for name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``dynid`` console script; returns the exit code.

    Run as the program (``argv`` None), the stop signals are ignored once the run is over:
    the interpreter resets their handlers as it exits, and a late Ctrl-C would kill it
    after a complete run, reported as interrupted (exit 130 beside a complete ``--out``).
    An interrupt is handled here, whatever code it stopped (:func:`_interrupt_handled`).
    Called in a process (``argv`` given), the root logger's level and handlers are left
    as they were: a ``-q`` run does not silence the next.
    """
    _one_blas_thread()
    root = logging.getLogger()
    level, handlers = root.level, list(root.handlers)
    try:
        return _main(argv)
    except KeyboardInterrupt:  # while the modules are imported, before the run's own handler
        if "--debug" in (sys.argv[1:] if argv is None else argv):
            raise
        command = _command(sys.argv[1:] if argv is None else argv)
        name = "dynid" if command is None else f"dynid {command.replace('_', '-')}"
        print(f"{name}: interrupted; no partial output left", file=_stderr())
        return 130
    finally:
        if argv is None:
            for sig in (signal.SIGINT, *TERMINATING):
                signal.signal(sig, signal.SIG_IGN)
        _interrupt_handled()
        if argv is not None:
            root.setLevel(level)
            for h in [h for h in root.handlers if h not in handlers]:
                root.removeHandler(h)


def _interrupt_handled() -> None:
    """Clear the interpreter's mark of a Ctrl-C left unhandled, which :func:`main` handles.

    CPython (3.11 to 3.13) marks a ``KeyboardInterrupt`` that leaves code run by ``exec``
    or ``eval`` of a string as unhandled, even when a caller catches it, and the program
    run by ``python -m`` then kills itself with SIGINT as it exits, after whatever status
    it returned: dataclasses and namedtuple build their methods with ``exec``, so a Ctrl-C
    while the modules load ended ``python -m dynid`` by the signal after its one line (5
    runs in 40 interrupted in their first second) instead of exit 130. Each ``exec`` of a
    string clears the mark as it starts; an empty one clears it and runs nothing. An
    interrupt that ``main`` lets through (``--debug``) is marked again where it leaves.
    """
    exec("")


def _main(argv: Sequence[str] | None) -> int:
    from .._checks import one_line
    from ..io.atomic import output_transaction
    from ..progress import reporting
    from ..report import REPORT_NAME
    from .applies import check_applies, given_options
    from .console import Console, log_to_stderr
    from .run_report import RunRecord, save_run_report

    _printable_streams()
    argv = join_negative_values(sys.argv[1:] if argv is None else list(argv))
    command = _command(argv)
    parser = build_parser(SUBCOMMANDS if command is None else (command,))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a refused option (one line printed)
        return exc.code if isinstance(exc.code, int) else 2
    decode_text_options(args)
    level = (
        logging.ERROR
        if args.quiet
        else (logging.DEBUG if args.verbose > 1 else logging.INFO if args.verbose else NOTE)
    )
    log_to_stderr(args.command, level)
    say = f"dynid {args.command}"
    record = RunRecord()
    console = Console(args.command, quiet=args.quiet, verbose=args.verbose, record=record)
    given: frozenset[str] = frozenset()
    try:
        given = given_options(parser, argv)
        check_applies(args, given, args._applies)
        with (
            record,
            _signals_and_warnings(console),
            output_transaction(),
            _output_set(args, argv) as run,
            reporting(console.progress_callback()),  # a long run's steps, on a terminal
        ):
            code = int(args._run(args, console) or 0)
            _raise_if_terminated()
            if run is not None and run.kind == "folder" and args._report:
                save_run_report(run, record, args, argv, code)
                console.print(f"report: {Path(args.out) / REPORT_NAME}")
        if record.stdout_closed:
            _drop_stdout()
            return STDOUT_CLOSED
        return code
    except KeyboardInterrupt:
        if args.debug:
            raise
        print(f"{say}: interrupted; no partial output left", file=_stderr())
        return 130
    except Terminated as exc:
        if args.debug:
            raise
        signum = int(exc.args[0]) if exc.args else int(signal.SIGTERM)
        print(
            f"{say}: terminated ({signal.Signals(signum).name}); no partial output left",
            file=_stderr(),
        )
        return 128 + signum
    except (DynidError, OSError) as exc:
        if args.debug:
            raise
        said = one_line(_message(exc, args, given), ERROR_LINE_LIMIT)
        print(f"{say}: error: {said}", file=_stderr())
        return 2
    except MemoryError as exc:
        if args.debug:
            raise
        print(f"{say}: error: {out_of_memory(exc, args.command)}", file=_stderr())
        return 2
    except Exception as exc:  # anything unexpected: one line, never a traceback
        if args.debug:
            raise
        print(
            f"{say}: error: unexpected {type(exc).__name__}: "
            f"{one_line(str(exc), ERROR_LINE_LIMIT)} (run with --debug for the traceback)",
            file=_stderr(),
        )
        return 2


def _message(
    exc: BaseException, args: argparse.Namespace | None = None, given: frozenset[str] = frozenset()
) -> str:
    """An error's line: an option named by its flag (:func:`dynid.cli.common.flag`); a
    missing input file named with its option (:func:`dynid.cli.common.missing_input`); a
    suggested ``dynid import`` given the robot options typed (``given``:
    :func:`dynid.cli.common.import_robot`)."""
    if isinstance(exc, OptionError):
        from .common import option_message

        return option_message(exc)
    from .common import cli_text, import_robot, missing_input

    if isinstance(exc, FileNotFoundError) and exc.filename is not None:
        said = None if args is None else missing_input(args, exc.filename)
        return said or f"{Path(exc.filename).name}: {exc.filename} does not exist"
    text = cli_text(str(exc))
    return text if args is None else import_robot(text, args, given)


#: What makes each command's memory smaller, for the out-of-memory hint (the commands that
#: read a torque log share the last entry).
_SMALLER = {
    "acquire-static": "or give fewer configurations (--n, --pool)",
    "simulate": "or give a shorter log (--duration, --rate)",
}
_LOG_COMMANDS = ("identify", "validate", "friction", "payload", "import")
_SMALLER_LOG = (
    "or give a shorter log (a long one streams its regressor in blocks above "
    "DYNID_MAX_STACK_BYTES bytes: lower it)"
)


def out_of_memory(exc: MemoryError, command: str | None = None) -> str:
    """One line for a process out of memory: the step (the innermost dynid function) and
    how to raise the limit or, for ``command``, what to make smaller."""
    where = "?"
    tb = exc.__traceback__
    while tb is not None:
        mod = str(tb.tb_frame.f_globals.get("__name__", ""))
        if mod.startswith("dynid."):
            where = f"{tb.tb_frame.f_code.co_name} ({mod})"
        tb = tb.tb_next
    smaller = _SMALLER_LOG if command in _LOG_COMMANDS else _SMALLER.get(command or "", "")
    return (
        f"out of memory in {where}; hint: the limit is the process's address space (ulimit "
        f"-v) or the machine's memory: raise it{', ' + smaller if smaller else ''}"
    )


def _stderr() -> TextIO:
    """Where the last line goes: stderr, or nowhere when the run started with file
    descriptor 2 closed (``2>&-``; ``print(file=None)`` would write it to stdout)."""
    return sys.stderr if sys.stderr is not None else io.StringIO()


def _drop_stdout() -> None:
    """Point stdout at the null device, so that the interpreter's last flush of a closed
    pipe cannot fail."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        sys.stdout.flush()
    with contextlib.suppress(OSError, ValueError, AttributeError):
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)


if __name__ == "__main__":
    sys.exit(main())
