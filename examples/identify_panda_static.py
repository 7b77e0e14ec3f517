"""Identify the Panda's 43 dynamic coefficients from M(q) and g(q) at static configurations.

Gaz et al. 2019, Sec. IV-A: the simulated controller returns M(q) and g(q) (with relative
noise) at 1010 random configurations; the stacked static regressor [tril M; g] in the base
parameters is solved by least squares. Prints the statistics and the largest errors
against the true (published) parameters.
"""

import numpy as np

import dynid

robot = dynid.panda()
controller = dynid.SimulatedController(robot, relative_noise=1e-4, rng=np.random.default_rng(1))
data = dynid.acquire_static(controller, 1010, np.random.default_rng(2))
model = dynid.identify_static(robot, data)

fit = model.fit
print(
    f"rank {fit.rank}, condition number {fit.condition_number:.3g}, "
    f"relative error {fit.relative_error_percent:.3g} %, "
    f"dropped rows {list(model.info.dropped_rows)}"
)
truth = model.base.beta_from_phi(robot.phi)
k = int(np.argmax(np.abs(model.beta - truth) / fit.std))
print(f"worst coefficient {model.base.labels[k]} = {model.base.expressions[k]}:")
print(f"  identified {model.beta[k]:+.6f} +- {fit.std[k]:.1e}, true {truth[k]:+.6f}")
q = np.random.default_rng(3).uniform(robot.q_min, robot.q_max, (1000, 7))
err = np.abs(model.gravity_torques(q) - dynid.gravity_torques(robot, q)).max()
print(f"largest gravity-torque error on 1000 held-out configurations: {err:.2e} N m")
