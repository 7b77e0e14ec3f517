"""Options and helpers shared by the subcommands: robot selection, vectors, argparse types
for checked option values, figures that are skipped without matplotlib."""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np

from .. import _checks, spatial
from .._checks import text as as_text
from ..exceptions import DataError, OptionError, ShapeError, in_file
from ..identification.torque_delay import AppliedDelay
from ..io.drive_file import drive_of_robot_file, load_drive, with_file_rotors
from ..io.robot_file import load_robot as load_robot_file
from ..kinematics.inverse import default_q0
from ..model.builtin import BUILTIN_ROBOTS
from ..model.robot import Robot
from ..plots.save import save_figure as write_figure
from ..progress import NOTE
from ..workflows.options import NO_FILTER
from ..workflows.prior import load_prior as workflow_prior
from .console import Console

_log = logging.getLogger(__name__)
_O = TypeVar("_O")


# ---------------------------------------------------------------------- options' flags
#: The flag of each option field of the library's entry points whose flag is not the
#: field's name with dashes (``drop_invalid`` -> ``--drop-invalid``): the one place where
#: an :class:`~dynid.exceptions.OptionError`'s ``field`` becomes what the user typed.
FLAGS: dict[str, str] = {
    "cutoff_hz": "--cutoff",
    "max_gap_s": "--max-gap",
    "torque_delay_s": "--torque-delay",
    "duration_s": "--duration",
    "rate_hz": "--rate",
    "jitter_s": "--jitter",
    "drop_fraction": "--drop",
    "base_freq_hz": "--base-freq",
    "contacts": "--contact",
    "law": "--friction-model",
    "merge_s": "--merge",
    "min_duration_s": "--min-duration",
    "label_tolerance_s": "--label-tolerance",
    "uncertainty": "--no-uncertainty",
    "standstill": "--no-standstill-margin",
    "loads": "--no-loads",
    "frictionloss": "--no-frictionloss",
    "total_mass_band": "--no-total-mass",
    "radii": "--radius",
    "ranges": "--range",
    "base_link": "--base",
    "tip_link": "--tip",
}


#: The options that name input files (:func:`missing_input`).
INPUT_FILES = (
    "data", "model", "thresholds", "validate_on", "obstacles", "friction", "trajectory",
    "params", "prior",
)  # fmt: skip


def missing_input(args: argparse.Namespace, filename: str | Path) -> str | None:
    """The line for an input file that does not exist, named with its option as
    ``--robot`` is (``nope.csv: --data: nope.csv does not exist``); None when ``filename``
    is none of the files of :data:`INPUT_FILES`."""
    for name in INPUT_FILES:
        value = getattr(args, name, None)
        for p in value if isinstance(value, list | tuple) else [value]:
            if isinstance(p, str | Path) and Path(p) == Path(filename) and not Path(p).exists():
                said = f"{Path(p).name}: {flag(name)}: {p} does not exist"
                parts = str(p).split(",")
                if len(parts) > 1 and all(Path(x).exists() for x in parts if x):
                    said += f"; hint: separate the files with spaces, {flag(name)} " + " ".join(
                        x for x in parts if x
                    )
                return said
    return None


#: The options of a run that ``dynid import`` takes too: its robot's and drive's, or the
#: identified model that holds both.
IMPORT_ROBOT_OPTIONS = ("model", "robot", "base", "tip", "snap_angles", "drive")


def import_robot(message: str, args: argparse.Namespace, given: frozenset[str]) -> str:
    """``message`` with each ``dynid import`` it suggests given the robot options the run
    was typed with (:data:`IMPORT_ROBOT_OPTIONS` among ``given``, their values ``args``'):
    ``dynid import train1.bag --robot arm.urdf --base b --tip t --out train1.csv``, the
    chain the run reads (:func:`dynid.workflows.data_files.with_import_robot`)."""
    if "dynid import" not in message:
        return message
    from ..workflows.data_files import with_import_robot

    options: list[str] = []
    for name in IMPORT_ROBOT_OPTIONS:
        value = getattr(args, name, None)
        if name not in given or value is None or value is False:
            continue
        options += [flag(name)] if value is True else [flag(name), str(value)]
    return with_import_robot(message, options)


def cli_text(message: str) -> str:
    """A library message as the command line says it: a Python option in a hint becomes
    its flag (:func:`flag`): a switch in parentheses, ``(drop_invalid=True)``, and an
    option of a value, ``max_std_percent=...`` (``hint: max_std_percent=... removes
    them`` -> ``hint: --max-std-percent removes them``); a flag the message already names
    is not repeated (``pass --drop-invalid (drop_invalid=True)`` -> ``pass
    --drop-invalid``). A string option given its value, ``units='tau=mA'``, becomes the
    flag and the value, ``--units tau=mA``. A ``name=...`` that is a flag's own value
    (``--units tau=...``, ``--q=...``) or an XML attribute (``<mass value=...>``) stays as
    it is."""
    out = re.sub(r"\((\w+)=True\)", lambda m: f"({flag(m.group(1))})", message)
    out = _PYTHON_VALUE.sub(lambda m: _value_flag(m, out), out)
    out = _PYTHON_OPTION.sub(lambda m: _option_flag(m, out), out)
    return re.sub(r"(--[\w-]+) \(\1\)", r"\1", out)


#: A Python option of a value named in a library message, ``name=...``: a word standing
#: alone (not an attribute's, a flag's or a longer name's end, nor after ``,`` or ``=``)
_PYTHON_OPTION = re.compile(r"(?<![\w.,=-])([a-z]\w*)=\.\.\.")


#: A Python string option given its value in a library message, ``units='tau=mA'``: a
#: word standing alone, the value quoted and without spaces.
_PYTHON_VALUE = re.compile(r"(?<![\w.,=-])([a-z]\w*)='([^'\s<>]+)'")


def _value_flag(m: re.Match[str], text: str) -> str:
    """The flag and value of the option ``m`` matched in ``text``, ``--units tau=mA``, or
    the match itself inside an XML tag."""
    before = text[: m.start()]
    if before.rfind("<") > before.rfind(">"):
        return m.group(0)
    return f"{flag(m.group(1))} {m.group(2)}"


def _option_flag(m: re.Match[str], text: str) -> str:
    """The flag of the option ``m`` matched in ``text``, or the match itself where it is a
    flag's value (after ``--units ``) or inside an XML tag (``<mass value=...>``)."""
    before = text[: m.start()]
    if re.search(r"--[\w-]+ $", before) or before.rfind("<") > before.rfind(">"):
        return m.group(0)
    return flag(m.group(1))


def flag(field: str) -> str:
    """The command-line flag of the option field ``field`` (:data:`FLAGS`)."""
    return FLAGS.get(field, "--" + field.replace("_", "-"))


def options_from(args: argparse.Namespace, cls: type[_O], **given: Any) -> _O:
    """The typed options ``cls`` (a dataclass of a library entry point) from the parsed
    command line: each field from its flag's value (:func:`flag`), or from ``given``
    (values the command parses or loads first); fields without a flag keep their default."""
    kw = {}
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        dest = flag(f.name)[2:].replace("-", "_")
        if f.name in given:
            kw[f.name] = given[f.name]
        elif hasattr(args, dest):
            kw[f.name] = getattr(args, dest)
    return cls(**kw)


def option_message(exc: OptionError) -> str:
    """An :class:`~dynid.exceptions.OptionError`'s message with its options named by their
    flags (``cutoff_hz must be ...`` -> ``--cutoff must be ...``)."""
    if exc.field is None:
        return str(exc)
    return OptionError.named(exc.reason, exc.field, exc.others, flag)


# ---------------------------------------------------------------------- option value types
def number(
    kind: type = float,
    *,
    min: float | None = None,
    max: float | None = None,
    min_open: bool = False,
    max_open: bool = False,
) -> Callable[[str], Any]:
    """An argparse ``type``: a finite ``int`` or ``float`` in a range, else a one-line error.

    ``number(int, min=0)`` is a seed, ``number(float, min=0, min_open=True)`` a positive
    float; NaN and infinities are always refused.
    """
    lo = "" if min is None else f"{'>' if min_open else '>='} {min:g}"
    hi = "" if max is None else f"{'<' if max_open else '<='} {max:g}"
    want = " and ".join(x for x in (lo, hi) if x)
    label = "an integer" if kind is int else "a finite number"

    def parse(text: str) -> Any:
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be {label}{' ' + want if want else ''}; got {text!r}"
            ) from None
        bad = not math.isfinite(v)
        if min is not None:
            bad |= v <= min if min_open else v < min
        if max is not None:
            bad |= v >= max if max_open else v > max
        if bad:
            raise argparse.ArgumentTypeError(
                f"must be {label}{' ' + want if want else ''}; got {text!r}"
            )
        return v

    parse.__name__ = kind.__name__  # argparse names the type in some messages
    return parse


#: ``--seed``: a non-negative integer (numpy's SeedSequence refuses negative ones).
seed_type = number(int, min=0)
#: Counts such as ``--n``, ``--runs``: positive integers.
count_type = number(int, min=1)
#: Positive finite floats (rates, durations, cutoffs, tolerances).
positive_type = number(float, min=0, min_open=True)
#: Non-negative finite floats (noise levels, margins).
nonnegative_type = number(float, min=0)


def cutoff_type(text: str) -> float | str:
    """The ``--cutoff`` argument: a positive frequency [Hz], or ``none`` (no low-pass:
    :data:`~dynid.workflows.options.NO_FILTER`)."""
    if text.strip().lower() in ("none", "off"):
        return NO_FILTER
    try:
        return positive_type(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"must be a finite frequency > 0 [Hz], or none (no low-pass); got {text!r}"
        ) from None


cutoff_type.__name__ = "cutoff"
#: The end of every ``--cutoff`` help: how to turn the filter off.
CUTOFF_NONE_HELP = (
    "; 'none': no low-pass, every sample as recorded (exact or already filtered data); a "
    "cut-off, given or the model's, not below half a log's rate runs at a quarter of the "
    "rate, with a note (one at or above the rate itself is refused)"
)


def add_subcommand(
    subparsers: argparse._SubParsersAction, name: str, doc: str | None, *, help: str
) -> argparse.ArgumentParser:
    """Add the subcommand ``name``: ``help`` is its line in ``dynid --help``, ``doc`` (the
    module docstring) its ``--help`` text, shown as written."""
    return subparsers.add_parser(
        name,
        help=help,
        description=doc,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def output_path(text: str) -> Path:
    """The ``--out`` argument: a path, never empty (``Path("")`` is the current folder, so an
    unset shell variable in ``--out "$DIR"`` would write there)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty (give a file or folder name)")
    return Path(text)


def add_seed_option(p: argparse.ArgumentParser, help: str = "random seed (default: 0)") -> None:
    """``--seed N`` (N >= 0)."""
    p.add_argument("--seed", type=seed_type, default=0, metavar="N", help=help)


def add_log_options(
    p: argparse.ArgumentParser,
    *,
    drop_invalid: bool = True,
    torque_delay: Literal["given", "recorded"] | None = None,
    recorded: bool = True,
) -> None:
    """``--max-gap SECONDS`` and ``--drop-invalid`` for commands that read a torque log;
    with ``torque_delay``, ``--torque-delay MS`` (:func:`add_torque_delay`: ``"recorded"``
    for a command whose default is the identification's); ``recorded``: the gap rule's
    default is a ``--model``'s identification's."""
    p.add_argument(
        "--max-gap",
        type=positive_type,
        default=None,
        metavar="SECONDS",
        help="longest gap in the log bridged by interpolation [s] (default: "
        + ("a --model's identification's, else " if recorded else "")
        + "2.5 median steps, at least 0.02 s; a log at any rate from 10 Hz up passes)",
    )
    if drop_invalid:
        add_drop_invalid(p)
    if torque_delay is not None:
        add_torque_delay(p, recorded=torque_delay == "recorded")


def milliseconds_type(text: str) -> float:
    """A finite number of milliseconds, returned in seconds."""
    ms = number(float)(text)
    if not math.isfinite(ms):
        raise argparse.ArgumentTypeError(f"expected a finite number of milliseconds; got {text!r}")
    return ms / 1000.0


def add_torque_delay(p: argparse.ArgumentParser, *, recorded: bool = False) -> None:
    """``--torque-delay MS``: how far the torques lag the positions, for commands that
    prepare a torque log (``recorded``: the default is the identification's)."""
    default = (
        "the delay the model was identified with, 0 for a robot file"
        if recorded
        else "0: the torques as recorded"
    )
    p.add_argument(
        "--torque-delay",
        dest="torque_delay",
        type=milliseconds_type,
        default=None,
        metavar="MS",
        help="how far the torques lag the positions [ms] (a filtered sensor, bus latency; "
        "positive: the torques late): each piece's states are read that much earlier, by "
        "a spline, before filtering (the torques as measured), and the samples at its ends "
        "that this reads beyond are dropped; identify and validate estimate it from the "
        f"residual and say it when it matters (default: {default}"
        + (
            "; the summary and the report say which, --torque-delay 0 turns it off)"
            if recorded
            else ")"
        ),
    )


def say_torque_delay(console: Console, applied: AppliedDelay | None) -> None:
    """Print the torques' delay a run prepared its logs with (``torque delay 3.0 ms (from
    the model's identification.json)``) and show it as ``--torque-delay``'s value in the
    report; nothing when none was given or recorded."""
    if applied is None:
        return
    console.print(applied.sentence())
    console.option_used("torque_delay", applied.text())


def add_drop_invalid(p: argparse.ArgumentParser) -> None:
    """``--drop-invalid``: the option the readers' error messages name as the remedy."""
    p.add_argument(
        "--drop-invalid",
        action="store_true",
        help="drop rows with NaN, inf, empty cells or a repeated timestamp (reported: "
        "how many and where) instead of failing (default: so where --model was identified "
        "with --drop-invalid, said in a note)",
    )


def shown(text: str) -> str:
    """``text`` as it can be drawn: a file name given under an ASCII locale (its UTF-8
    bytes escaped as surrogates, ``l\\udcc3\\udcb6g.csv``) back to its characters
    (``l\u00f6g.csv``); bytes that are not UTF-8 become U+FFFD."""
    return as_text(text)


def add_robot_options(p: argparse.ArgumentParser) -> None:
    """``--robot panda|fr3|FILE.urdf|FILE.toml`` with ``--base``/``--tip`` for URDF chains."""
    p.add_argument(
        "--robot",
        default="panda",
        help="'panda', 'fr3' (the Panda's link parameters), a .urdf or a .toml file "
        "(default: panda)",
    )
    p.add_argument("--base", default=None, help="URDF base link of the chain (default: the root)")
    p.add_argument(
        "--tip", default=None, help="URDF tip link of the chain (default: the only leaf)"
    )
    add_snap_angles_option(p)


def add_snap_angles_option(p: argparse.ArgumentParser, robot: str = "--robot") -> None:
    """``--snap-angles`` for the URDF of ``robot``: every command that reads a URDF and
    may print the rounded-angle warning's hint takes it."""
    p.add_argument(
        "--snap-angles",
        action="store_true",
        help=f"a URDF {robot}: read joint angles within 1e-3 rad of a multiple of pi/2 as "
        'that multiple (rpy="1.5708" as pi/2); without it such rounded angles are read as '
        "written and named in a note with the leftovers and condition numbers they cause "
        "(angles snapped are named too)",
    )


def add_drive_option(p: argparse.ArgumentParser) -> None:
    """``--drive FILE.toml``: the drive train (gear ratios, coupling, offsets, currents)."""
    p.add_argument(
        "--drive",
        type=Path,
        default=None,
        metavar="FILE.toml",
        help="drive train (schema dynid-drive/1: side, gear_ratio, coupling, offset, effort, "
        "torque_constant, rotor_inertia, friction_at; see the README); default: the [drive] "
        "table of a robot TOML (--robot, --params), else link-side torques of a direct drive. "
        "A robot description's own friction (URDF <dynamics>, MJCF damping/frictionloss) "
        'stays at the joints unless the file says friction_at = "motor"',
    )


def numbers_type(text: str) -> tuple[float, ...]:
    """An argparse ``type``: comma-separated finite numbers (``-0.1,0.2``), else a one-line
    error; the count is checked where the robot is known."""
    try:
        v = tuple(float(x) for x in text.replace(" ", "").split(",") if x != "")
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be comma-separated numbers; got {text!r}") from None
    if not v or not all(math.isfinite(x) for x in v):
        raise argparse.ArgumentTypeError(f"must be comma-separated finite numbers; got {text!r}")
    return v


def add_q_start_option(p: argparse.ArgumentParser) -> None:
    """``--q-start Q1,...,QN``: the joint positions at a motor-side log's first sample,
    which tell the whole turns of motors recorded wrapped (one definition for every
    command that reads logs through a drive)."""
    p.add_argument(
        "--q-start",
        type=numbers_type,
        default=None,
        metavar="Q1,...,QN",
        help="joint positions [rad] at the first sample of a motor-side log (one log) whose "
        "motor encoders wrap every turn: the motors' whole turns are those that put the "
        "joints nearest them (needed when the joint limits leave several)",
    )


def load_drive_arg(args: argparse.Namespace, n: int, *, robot_rotors: bool = False) -> Any:
    """The :class:`~dynid.model.drive.Drive` of ``--drive`` (or of a --robot TOML's
    ``[drive]`` table, or the one a --robot feasible.json holds), or None. With
    ``robot_rotors`` (a command that validates a description), a ``--drive`` that leaves
    the rotor inertias to identify takes the --robot file's
    (:func:`~dynid.io.drive_file.with_file_rotors`), said in a note."""
    if getattr(args, "drive", None) is not None:
        drive = load_drive(args.drive, n)
        spec = getattr(args, "robot", None)
        if robot_rotors and spec is not None and Path(str(spec)).is_file():
            drive, said = with_file_rotors(drive, spec, n)
            if said is not None:
                _log.log(NOTE, said)
        return drive
    spec = getattr(args, "robot", None)
    if spec is not None and str(spec).lower().endswith(".json") and Path(spec).is_file():
        from ..io.feasible import load_feasible_drive  # here: one-shot commands skip scipy

        return load_feasible_drive(spec)  # a feasible.json's drive, if it holds one
    return None if spec is None else drive_of_robot_file(spec, n)


def load_robot(args: argparse.Namespace, *, parameters: bool = True) -> Robot:
    """The robot named by ``--robot`` (and ``--base``/``--tip``/``--snap-angles`` for a
    URDF); ``parameters`` False for a command of the kinematics alone (no note on a built-in
    robot's link parameters).

    Raises
    ------
    OptionError
        ``--base``, ``--tip`` or ``--snap-angles`` with a robot that is not a URDF.
    """
    spec = args.robot
    snap = bool(getattr(args, "snap_angles", False))
    chain = {"base": args.base, "tip": args.tip, "snap_angles": snap}
    if spec in BUILTIN_ROBOTS:
        return load_robot_file(spec, **chain, what="--robot", parameters=parameters)
    path = Path(spec)
    with in_file(path.name):
        return load_robot_file(path, **chain, what="--robot")


def add_consistency_options(p: argparse.ArgumentParser) -> None:
    """Options of the convex (SDP) route: prior, its weight, objective, margin, mass band."""
    g = p.add_argument_group("physically consistent parameters (convex, LMI)")
    g.add_argument(
        "--prior",
        default=None,
        metavar="generic|panda|fr3|FILE",
        help="prior link parameters: 'generic' (a solid cylinder per link from the "
        "kinematics), 'panda', 'fr3' (the Panda's), a .urdf (with --prior-base/--prior-tip), "
        "a .toml or a feasible.json; default: the --robot description's own inertials "
        "(generic when it has none)",
    )
    g.add_argument("--prior-base", default=None, help="URDF base link of the prior's chain")
    g.add_argument("--prior-tip", default=None, help="URDF tip link of the prior's chain")
    g.add_argument(
        "--prior-weight",
        type=positive_type,  # > 0: without the prior, what the data leave free has no one value
        default=None,
        metavar="W",
        help="weight of the distance to the prior (default, printed: from a torque log the "
        "largest whose held-out error is within 1 %% of the best weight's; from coefficients "
        "or static data the largest that keeps the data residual RMS within 1 %% of the "
        "unconstrained fit)",
    )
    g.add_argument(
        "--objective",
        choices=("logdet", "euclidean"),
        default=None,
        help="distance to the prior: log-det (Bregman) divergence (default) or Euclidean",
    )
    g.add_argument(
        "--margin",
        type=number(float, min=0, max=0.25, max_open=True),
        default=None,
        metavar="EPS",
        help="every link's lambda_min(J) >= EPS tr(J) (pseudo-inertia J; default 1e-4)",
    )


def load_prior(args: argparse.Namespace, robot: Robot, console: Console) -> Robot | None:
    """The prior robot named by ``--prior`` (None: the robot's own inertials, or the generic
    prior without any), checked against
    ``robot`` (:func:`dynid.workflows.prior.load_prior`; a built-in prior's note on its
    parameters is logged where its name is resolved,
    :func:`~dynid.model.builtin.builtin_robot`)."""
    return workflow_prior(args.prior, robot, base=args.prior_base, tip=args.prior_tip)


def parse_mass_band(text: str | None) -> tuple[float, float] | None:
    """``--total-mass MIN,MAX`` [kg] (0 <= MIN <= MAX), or None."""
    if text is None:
        return None
    v = parse_vector(text, "--total-mass", 2)
    if not 0.0 <= v[0] <= v[1]:
        raise DataError(f"--total-mass must be MIN,MAX, 0 <= MIN <= MAX; got {text}")
    return float(v[0]), float(v[1])


def parse_vector(
    text: str, name: str, size: int | None = None, *, finite: bool = True
) -> np.ndarray:
    """Comma-separated floats (negative values welcome: ``--q -0.1,0.2``); ``size`` checks
    the count, ``finite`` refuses NaN and infinities."""
    try:
        v = np.array([float(x) for x in text.replace(" ", "").split(",") if x != ""])
    except ValueError:
        raise ShapeError(f"{name} must be comma-separated numbers; got {text!r}") from None
    if size is not None and v.shape != (size,):
        raise ShapeError(f"{name} must have {size} values; got {v.size}")
    if finite:
        _checks.finite(name, v)
    return v


def save_figure(fig_factory: Callable[[], Any], path: Path, *, dpi: int = 110) -> Path | None:
    """Render ``fig_factory()`` to ``path`` with :func:`dynid.plots.save.save_figure`;
    when that fails for any reason (matplotlib missing or broken, a bad ``MPLBACKEND``, an
    error while drawing or writing), skip it with a one-line note on stderr and return None.

    Figures are optional: every data file is written before them, and a figure never
    fails a command.
    """
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print(f"note: matplotlib is not installed; skipped the figure {path.name}", file=sys.stderr)
        return None
    except Exception as exc:  # a broken installation or configuration
        _skipped(path, exc)
        return None
    try:
        return write_figure(fig_factory, path, dpi=dpi)
    except Exception as exc:
        _skipped(path, exc)
        return None


def _skipped(path: Path, exc: BaseException) -> None:
    reason = " ".join(f"{type(exc).__name__}: {exc}".split())
    if len(reason) > 200:
        reason = reason[:200] + " ..."
    print(f"note: skipped the figure {path.name}: {reason}", file=sys.stderr)
    _log.debug("figure %s", path.name, exc_info=exc)


def format_matrix(A: np.ndarray, fmt: str = "{:+.6f}") -> str:
    """A readable fixed-width table of a 2-D array."""
    return "\n".join("  ".join(fmt.format(v) for v in row) for row in np.atleast_2d(A))


# ---------------------------------------------------------------------- kinematics options
def add_q_option(p: argparse.ArgumentParser) -> None:
    """``--q`` joint positions, defaulting to the documented start pose."""
    p.add_argument(
        "--q",
        default=None,
        metavar="Q1,...,QN",
        help="joint positions [rad or m], comma-separated (default: the neutral pose)",
    )


def joint_positions(args: argparse.Namespace, robot: Robot) -> np.ndarray:
    """``--q`` parsed, or the documented start pose."""
    return default_q0(robot) if args.q is None else parse_q(args.q, robot)


def add_frame_tool_options(p: argparse.ArgumentParser) -> None:
    """``--frame NAME`` (default flange) and ``--tool x,y,z[,roll,pitch,yaw]``."""
    p.add_argument("--frame", default="flange", help="a frame of the robot (default: flange)")
    p.add_argument(
        "--tool",
        default=None,
        metavar="X,Y,Z[,R,P,Y]",
        help="a tool fixed to --frame: offset [m] and URDF roll, pitch, yaw [rad] in that frame",
    )


def parse_tool(text: str | None) -> np.ndarray | None:
    """``T_frame_tool`` (4, 4) from ``x,y,z[,roll,pitch,yaw]`` [m, rad], or None."""
    if text is None:
        return None
    v = parse_vector(text, "--tool")
    if v.size not in (3, 6):
        raise ShapeError(
            f"--tool must have 3 values (x,y,z) or 6 (x,y,z,roll,pitch,yaw); got {v.size}"
        )
    _checks.finite("--tool", v)
    return spatial.transform_from_xyz_rpy(v[:3], v[3:] if v.size == 6 else (0.0, 0.0, 0.0))


def parse_q(text: str, robot: Robot, name: str = "--q") -> np.ndarray:
    """Joint positions (n,) [rad or m] from comma-separated values, checked for count and NaN."""
    return parse_vector(text, name, robot.n)


def format_joint_table(robot: Robot, q: np.ndarray) -> str:
    """One line per joint: name, value [rad] and value [deg] (revolute joints)."""
    width = max(len(s) for s in robot.joint_names)
    lines = []
    for name, v, pri in zip(robot.joint_names, q, robot.prismatic, strict=True):
        unit = f"{v:+.6f} m" if pri else f"{v:+.6f} rad  ({np.degrees(v):+9.3f} deg)"
        lines.append(f"  {name:<{width}}  {unit}")
    return "\n".join(lines)


# ---------------------------------------------------------------------- data files
def add_recordings_option(p: argparse.ArgumentParser) -> None:
    """``--data``: one or more torque logs, or folders of them, each filtered on its own."""
    p.add_argument(
        "--data",
        type=Path,
        nargs="+",
        action="extend",
        required=True,
        help="torque log(s) (.csv or .npz), or a folder of them: each recording, and each "
        "piece between gaps longer than --max-gap, filtered on its own",
    )


def add_column_options(p: argparse.ArgumentParser) -> None:
    """``--columns`` (text or a .toml file) and ``--units`` for files of other tools."""
    p.add_argument(
        "--columns",
        default=None,
        metavar="MAP|FILE.toml",
        help="column names of --data: 'q=position_{i0},tau=effort_{i0}' ({i} from 1, {i0} "
        "from 0) or a TOML file with [columns] and [units]; observe also reads label=NAME "
        "(contact labels) and tau_ext=NAME{i0} (external torques, taken as the truth it is "
        "scored against); positions only: velocities "
        "from the zero-phase filtered derivative; dq=none reads the log without its velocity "
        "(and acceleration) columns, derived from the positions instead; ddq=none without "
        "its acceleration columns",
    )
    p.add_argument(
        "--units",
        default=None,
        metavar="MAP",
        help="units of --data: 'q=deg,dq=deg/s,tau=mNm,t=ms' (converted to SI, each "
        "quantity by its own entry: q=deg leaves dq as read; a length unit, q=mm, reads the "
        "prismatic joints, an angle unit the revolute ones, both given for both kinds: "
        "q=mm,q=deg,dq=mm/s,dq=deg/s; tau=mA or A: motor "
        "currents, with a --drive of effort = current; tau=-1 flips every joint's sign, "
        "tau2=-1 joint 2's alone, rec2.csv:tau2=-1 or rec2.csv:tau=-1 in that file alone; "
        "a file's own unit, rec4.csv:t=ms, in place of every file's for that file)",
    )
