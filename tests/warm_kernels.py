"""Compile the numba kernels into their disk cache before the test workers start.

On a clean checkout nothing is cached: the workers of ``make test`` (one a core) would each
compile the kernels the first test of theirs needs, the same kernel twice at once when two
tests need it together (the inverse kinematics alone takes about 13 s). The session
start of ``tests/conftest.py`` runs this module in one process per group, in parallel,
before the workers exist; they then load the kernels from the cache. Nothing here is
checked: a kernel left out is compiled by the first test that needs it, as before.

Usage: ``python tests/warm_kernels.py GROUP`` with GROUP 0 (the kinematics, forward and
inverse, the Jacobians and link poses and the regressors, each for a batch and one sample,
and the low-pass filter's sections:
about 25 s of one core's time) or 1 (the dynamics, the gravity torques included, and the
momentum observer: about 24 s).
No compiled function is called from both groups (the inverse kinematics' Jacobian is
inlined, the batch gravity torques call the RNEA kernel in its own group, and the
helpers compiled on their own and called keep no disk cache of their own): two
processes writing one function's cache index at once can lose an entry.
"""

from __future__ import annotations

import sys

import numpy as np

import dynid

GROUPS = 2


def warm(group: int) -> None:
    """Call every compiled kernel of ``group`` once on the Panda, batch then single sample."""
    robot = dynid.panda()
    q = np.array([0.1, -0.3, 0.2, -1.8, 0.1, 1.6, 0.4])
    Q = np.tile(q, (3, 1))
    for x, v in ((Q, Q), (q, q)):  # a batch first: it loads the kernels for single samples
        if group == 0:
            dynid.signals.lowpass(np.tile(x, (64, 1)), 1000.0, 10.0)  # its sections' kernel
            dynid.ik(robot, dynid.fk(robot, x), q0=x)
            dynid.jacobian(robot, x)
            dynid.link_poses(robot, x)
            dynid.static_regressor(robot, x)
            dynid.torque_regressor(robot, x, v, v)
            continue
        dynid.rnea(robot, x, v, v)
        dynid.gravity_torques(robot, x)  # its batch calls the RNEA kernel
        dynid.mass_matrix(robot, x)
        dynid.coriolis(robot, x, v)
        dynid.forward_dynamics(robot, x, v, v)
    if group == 1:  # the observer
        from dynid.observer import MomentumObserver, from_robot, momentum_terms

        momentum_terms(robot, Q, Q)
        obs = MomentumObserver(from_robot(robot))
        obs.run(np.arange(3.0), Q, Q, Q)
        obs.step(q, q, q, 5.0)


if __name__ == "__main__":
    warm(int(sys.argv[1]))
