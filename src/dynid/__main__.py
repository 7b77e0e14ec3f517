"""``python -m dynid``: the command-line interface."""

import sys

try:
    from .cli.__main__ import main
except KeyboardInterrupt:  # Ctrl-C while the (light) entry module loads
    print("dynid: interrupted; no partial output left", file=sys.stderr)
    exec("")  # clears CPython's mark of an interrupt left unhandled by exec'd code (namedtuple)
    sys.exit(130)

sys.exit(main())
