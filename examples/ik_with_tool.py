"""Move a tool fixed to the Panda's flange to a goal pose by inverse kinematics.

Shows: a tool frame (0.1 m along the flange z axis), its pose and Jacobian, and an IK solve
by kinematic simulation from the neutral pose, reporting the errors and the joint path.
"""

import numpy as np

import dynid

robot = dynid.panda()
T_flange_tool = np.eye(4)
T_flange_tool[2, 3] = 0.1  # [m]

q0 = dynid.PANDA_NEUTRAL_Q
T_goal = dynid.fk(robot, q0 + np.array([0.3, 0.2, -0.1, 0.3, 0.1, -0.2, 0.4]), tool=T_flange_tool)
J_tool = dynid.jacobian(robot, q0, "flange", tool=T_flange_tool)  # (6, 7), base frame

result = dynid.ik(robot, T_goal, q0, tool=T_flange_tool)
print(f"converged: {result.converged} after {result.iterations} steps")
print(
    f"position error {result.position_error:.2e} m, "
    f"orientation error {result.orientation_error:.2e} rad"
)
print("q [rad]:", np.array2string(result.q, precision=4))
print("joint path:", result.path.shape, "(steps + 1, joints)")
