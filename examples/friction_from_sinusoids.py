"""Fit the sigmoid joint friction of the Panda from a simulated sinusoidal motion.

Gaz et al. 2019, Sec. IV-B and VI: the robot follows the velocity-mode sinusoids of Table I
(scaled into Franka's limits) for 20 s at 1 kHz; measured torques include the published
friction and sensor noise. The friction is the residual of the rigid-body model; one
sigmoid per joint is fitted by Nelder-Mead, and the torque RMS drops to the noise level.
"""

import numpy as np

import dynid

robot = dynid.panda()
t = np.arange(0.0, 20.0, 0.001)
traj = dynid.sinusoid_trajectory(t, dynid.simulation.trajectories.centered_start(robot))
traj, scale = dynid.scale_into_limits(robot, traj)
log = dynid.simulate_measurement(robot, traj, rng=np.random.default_rng(0))

rigid = robot.with_friction(None)  # the rigid-body model only
fit = dynid.fit_friction(rigid, log)
print(f"amplitudes scaled by {scale:.3f} into the limits")
true = robot.friction.as_array()  # the sigmoid the simulation used
print(
    "joint  phi1 [N m]  phi2 [s/rad]  phi3 [rad/s]   RMS before -> after [N m]"
    "   (true phi1, phi2, phi3)"
)
for j, (p1, p2, p3) in enumerate(fit.friction.as_array()):
    print(
        f"{j + 1:>5}  {p1:10.4f}  {p2:12.3f}  {p3:+12.5f}   "
        f"{fit.rms_before[j]:.3f} -> {fit.rms_after[j]:.3f}"
        f"   ({true[j, 0]:.4f}, {true[j, 1]:.3f}, {true[j, 2]:+.5f})"
    )
