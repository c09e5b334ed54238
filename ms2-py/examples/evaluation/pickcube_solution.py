"""A PickCube-v0 solution for ``ms2 evaluate``: a hand-written controller on ``state_dict``
observations in ``pd_ee_delta_pos`` (end-effector position deltas).

    ms2 evaluate --env-id PickCube-v0 --solution ms2-py/examples/evaluation/pickcube_solution.py \
        -n 10 -o results/pickcube

It moves the gripper 5 cm above the cube, lowers it onto the cube, closes the fingers for a
few steps and carries the cube to the goal. Only the observation is used (no privileged
state), as in a submission.
"""

import numpy as np
from ms2.evaluation.solution import BasePolicy

#: Metres per unit of pd_ee_delta_pos's normalized action (ManiSkill2's ±0.1 m).
ACTION_SCALE = 0.1
#: Proportional gain: the fraction of the remaining distance covered per step.
GAIN = 5.0
#: Steps with the fingers closing before lifting.
GRASP_STEPS = 6


def rotation_matrix(wxyz):
    """The 3×3 rotation of a unit quaternion (w, x, y, z)."""
    w, x, y, z = wxyz
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


class UserPolicy(BasePolicy):
    """Approach, grasp, carry: a three-phase proportional controller."""

    def reset(self, observations):
        self.phase = "approach"
        self.grasp_steps = 0

    def act(self, observations):
        extra = observations["extra"]
        tcp_pose = extra["tcp_pose"]
        tcp, cube, goal = tcp_pose[:3], extra["obj_pose"][:3], extra["goal_pos"]
        gripper = 1.0  # open
        if self.phase == "approach":
            target = cube + np.array([0.0, 0.0, 0.05])
            if np.linalg.norm(target - tcp) < 0.01:
                self.phase = "descend"
        if self.phase == "descend":
            target = cube
            if np.linalg.norm(target - tcp) < 0.005:
                self.phase = "grasp"
        if self.phase == "grasp":
            target, gripper = cube, -1.0
            self.grasp_steps += 1
            if self.grasp_steps > GRASP_STEPS:
                self.phase = "carry"
        if self.phase == "carry":
            target, gripper = goal, -1.0
        # The deltas are in the end-effector's frame: rotate the world-frame error into it.
        delta = rotation_matrix(tcp_pose[3:]).T @ (target - tcp)
        move = np.clip(delta / ACTION_SCALE * GAIN, -1.0, 1.0)
        return np.append(move, gripper).astype(np.float32)

    @classmethod
    def get_obs_mode(cls, env_id):
        return "state_dict"

    @classmethod
    def get_control_mode(cls, env_id):
        return "pd_ee_delta_pos"
