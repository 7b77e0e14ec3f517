"""The ``dynid`` commands of the documentation's pages, each a process forked from one
that has imported the command line already (:mod:`docs_pages` runs the pages).

A page's commands spent most of a second each importing numpy, scipy, matplotlib and the
library before they did anything. ``python docs_commands.py serve SOCKET`` imports every
subcommand's modules and the scipy subpackages the commands import inside their functions
(:data:`SCIPY`: ``scipy.signal`` alone took over a second, most of it parsing docstrings;
not numba: a one-sample call without numba loaded takes the numpy path, as a fresh process
does) and listens on the Unix socket ``SOCKET``; ``python
docs_commands.py run SOCKET ARGS...`` (the ``dynid`` of a page's ``PATH``) hands it the
arguments, its working folder, environment and standard streams, and exits as the forked
command did. Each command is thus a process of its own, as written on the page: its own
memory, signals, exit status and streams, the environment of the page.

The first call of each subcommand, and any call whose environment differs from the
server's in more than ``PATH`` and the shell's own variables (one may set an option read
while a module is imported), runs in a fresh interpreter (``python -m dynid``) instead:
the pages keep checking that a command imports what it needs on its own.
"""

from __future__ import annotations

import array
import json
import os
import selectors
import signal
import socket
import sys

#: variables whose difference does not change what the server imported
_FREE = frozenset({"PATH", "PWD", "OLDPWD", "SHLVL", "_", "PYTEST_CURRENT_TEST"})
_FRESH = b"fresh"
#: the scipy subpackages a page's commands import inside their functions (none loads numba)
SCIPY = (
    "scipy.fft", "scipy.integrate", "scipy.interpolate", "scipy.linalg", "scipy.ndimage",
    "scipy.optimize", "scipy.signal", "scipy.sparse", "scipy.spatial", "scipy.special",
    "scipy.stats",
)  # fmt: skip


def _comparable(env: dict[str, str]) -> dict[str, str]:
    """``env`` without the variables of :data:`_FREE`."""
    return {k: v for k, v in env.items() if k not in _FREE}


def _recv_request(conn: socket.socket) -> tuple[dict, list[int]]:
    """The request (JSON, one message) and the client's standard streams' descriptors."""
    fds = array.array("i")
    data, ancdata, _, _ = conn.recvmsg(1 << 20, socket.CMSG_SPACE(3 * fds.itemsize))
    for level, kind, payload in ancdata:
        if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
            fds.frombytes(payload[: len(payload) - len(payload) % fds.itemsize])
    return json.loads(data), list(fds)


def _child(conn: socket.socket, listener: socket.socket, request: dict, fds: list[int]) -> None:
    """In the forked process: become the command (streams, folder, environment, argv)."""
    listener.close()
    conn.close()
    for target, fd in enumerate(fds):
        os.dup2(fd, target)
    for fd in fds:
        if fd > 2:
            os.close(fd)
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    sys.stdout.reconfigure(line_buffering=os.isatty(1))
    sys.argv = [request["main"], *request["argv"]]
    from dynid.cli.__main__ import main

    sys.exit(main())  # the interpreter's own exit: atexit, threads, flushed streams


def serve(path: str) -> None:
    """Import the command line, then fork a command for each request on the socket ``path``."""
    import importlib

    import matplotlib.pyplot  # noqa: F401 (the figures of every command's report)

    import dynid
    from dynid.cli import __main__ as cli

    for name in (*(f"dynid.cli.{name}" for name in cli.SUBCOMMANDS), *SCIPY):
        importlib.import_module(name)
    if "numba" in sys.modules or not hasattr(os, "pidfd_open"):
        # (numba loaded would change the numpy paths of one-sample calls)
        raise SystemExit("docs_commands: every command runs fresh")
    own = _comparable(dict(os.environ))
    seen: set[str | None] = set()
    main_path = os.path.join(os.path.dirname(dynid.__file__), "__main__.py")
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(path)
    listener.listen(16)
    sel = selectors.DefaultSelector()
    sel.register(listener, selectors.EVENT_READ)
    sel.register(sys.stdin, selectors.EVENT_READ)  # closed: the tests are over
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    while True:
        for key, _ in sel.select():
            if key.fileobj is sys.stdin:
                return
            if key.fileobj is listener:
                conn, _ = listener.accept()
                request, fds = _recv_request(conn)
                command = cli._command(request["argv"])
                if command not in seen or _comparable(request["env"]) != own:
                    seen.add(command)
                    conn.sendall(_FRESH)
                    conn.close()
                    for fd in fds:
                        os.close(fd)
                    continue
                request["main"] = main_path
                sys.stdout.flush()
                sys.stderr.flush()
                pid = os.fork()
                if pid == 0:
                    _child(conn, listener, request, fds)
                for fd in fds:
                    os.close(fd)
                sel.register(os.pidfd_open(pid), selectors.EVENT_READ, (pid, conn))
            else:
                pid, conn = key.data
                sel.unregister(key.fileobj)
                os.close(key.fd)
                _, status = os.waitpid(pid, 0)
                conn.sendall(str(status).encode())
                conn.close()


def run(path: str, argv: list[str]) -> None:
    """``dynid ARGV`` through the server at ``path``, else (or when it says so) fresh."""
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
            s.connect(path)
            request = {"argv": argv, "cwd": os.getcwd(), "env": dict(os.environ)}
            fds = array.array("i", [0, 1, 2])
            s.sendmsg([json.dumps(request).encode()], [(socket.SOL_SOCKET, socket.SCM_RIGHTS, fds)])
            reply = b""
            while chunk := s.recv(64):
                reply += chunk
    except OSError:
        reply = _FRESH
    if reply == _FRESH:
        os.execv(sys.executable, [sys.executable, "-m", "dynid", *argv])
    status = int(reply)
    if os.WIFSIGNALED(status):  # end as the command did
        sig = os.WTERMSIG(status)
        signal.signal(sig, signal.SIG_DFL)
        os.kill(os.getpid(), sig)
    sys.exit(os.waitstatus_to_exitcode(status))


if __name__ == "__main__":
    if sys.argv[1] == "serve":
        serve(sys.argv[2])
    else:
        run(sys.argv[2], sys.argv[3:])
