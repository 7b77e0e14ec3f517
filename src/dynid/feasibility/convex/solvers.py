"""cvxpy's Clarabel and SCS interfaces that let a stop signal (Ctrl-C, SIGTERM) end a solve.

* **Clarabel** runs in compiled code and never looks at Python's signals: a Ctrl-C waited
  for the whole solve (a 90 x 90 SDP: the signal at 2 s, the interrupt at 22 s). Its
  termination callback, called once per iteration, is no way through either: an exception
  raised in it (the interrupt Python delivers as the callback starts) is printed and
  dropped, and the solve ran on to "optimal" with no interrupt left. Here the stop signals
  are recorded instead of raised while the solver runs (main thread only), the callback
  ends the solve at the next iteration when one has arrived, and the signal is delivered
  again to its own handler once the solver has returned: a :class:`KeyboardInterrupt` (or
  the command line's termination) before cvxpy reads the status, so no retry follows.
* **SCS** catches SIGINT itself and returns its status -5, which cvxpy reports as a failed
  solve (a retry, or the rest of the run, would go on as if nothing were asked); here it is
  a :class:`KeyboardInterrupt`.
"""

from __future__ import annotations

import contextlib
import functools
import signal
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["SCS_SIGINT", "STOP_SIGNALS", "clarabel", "scs", "stop_signals_recorded"]

#: SCS's status after it caught SIGINT.
SCS_SIGINT = -5
#: The signals that stop a run (the command line turns them into exits).
STOP_SIGNALS = tuple(
    getattr(signal, s) for s in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT") if hasattr(signal, s)
)


@contextlib.contextmanager
def stop_signals_recorded() -> Iterator[list[int]]:
    """Inside the block, the stop signals whose handler is a Python function are recorded
    (in the yielded list) instead of handled; when the block ends they are raised again,
    in the order they came, to the handlers they had. Outside the main thread (where no
    handler can be set) the block changes nothing."""
    arrived: list[int] = []
    handlers: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for s in STOP_SIGNALS:
            h = signal.getsignal(s)
            if callable(h):  # SIG_DFL and SIG_IGN keep their meaning
                handlers[s] = h
                signal.signal(s, lambda signum, frame: arrived.append(signum))
    try:
        yield arrived
    finally:
        for s, h in handlers.items():
            signal.signal(s, h)
        for s in dict.fromkeys(arrived):
            signal.raise_signal(s)


@functools.cache
def clarabel() -> Any:
    """cvxpy's Clarabel interface whose solve a stop signal ends (module docstring).

    One instance per process: cvxpy keeps a problem's compiled form (its parameters
    substituted at each solve) only while the solver is the same object; a new one each
    solve compiled the problem again, about ten times Clarabel's own time.
    """
    from cvxpy.reductions.solvers.conic_solvers.clarabel_conif import CLARABEL

    class InterruptibleClarabel(CLARABEL):
        def name(self) -> str:
            return "DYNID_CLARABEL"  # (cvxpy refuses a custom solver under a built-in name)

        def solve_via_data(
            self,
            data: Any,
            warm_start: bool,
            verbose: bool,
            solver_opts: Any,
            solver_cache: Any = None,
        ) -> Any:
            import clarabel as cl
            import cvxpy.settings as s
            import scipy.sparse as sp
            from cvxpy.reductions.solvers.conic_solvers.clarabel_conif import (
                dims_to_solver_cones,
            )
            from cvxpy.reductions.solvers.conic_solvers.conic_solver import ConicSolver

            q = data[s.C]
            P = data[s.P] if s.P in data else sp.csc_array((q.size, q.size))
            solver = cl.DefaultSolver(
                sp.triu(P).tocsc(),
                q,
                data[s.A],
                data[s.B],
                dims_to_solver_cones(data[ConicSolver.DIMS]),
                self.parse_solver_opts(verbose, solver_opts),
            )
            with stop_signals_recorded() as arrived:
                solver.set_termination_callback(lambda info: bool(arrived))
                return solver.solve()  # a recorded signal is raised before this returns

    return InterruptibleClarabel()


@functools.cache
def scs() -> Any:
    """cvxpy's SCS interface that lets a Ctrl-C through (module docstring); one instance
    per process, as :func:`clarabel`."""
    from cvxpy.reductions.solvers.conic_solvers.scs_conif import SCS

    class InterruptibleSCS(SCS):
        def name(self) -> str:
            return "DYNID_SCS"  # (cvxpy refuses a custom solver under a built-in name)

        def invert(self, solution: Any, inverse_data: Any) -> Any:
            if solution["info"]["status_val"] == SCS_SIGINT:
                raise KeyboardInterrupt
            return super().invert(solution, inverse_data)

    return InterruptibleSCS()
