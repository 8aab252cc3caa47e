"""Pendulum swing-up in plain Python and numpy, as Gymnasium's Pendulum-v1.

theta'' = 3g/(2l) sin(theta) + 3/(m l^2) u with g = 10, m = l = 1, steps
of 0.05 s, the speed clipped to [-8, 8] and the torque u to [-2, 2];
reward -(theta^2 + 0.1 theta'^2 + 0.001 u^2) with theta normalised to
[-pi, pi); observation (cos theta, sin theta, theta'); 200 steps. It
offers no get_state(): a resumed run restarts its episodes.
"""

import numpy as np

from spaces import Box

MAX_SPEED = 8.0
MAX_TORQUE = 2.0
DT = 0.05
G = 10.0


class Pendulum:
    def __init__(self, g=G):
        self.g = g
        high = np.array([1.0, 1.0, MAX_SPEED], dtype=np.float32)
        self.observation_space = Box(-high, high, dtype=np.float32)
        self.action_space = Box(-MAX_TORQUE, MAX_TORQUE, shape=(1,),
                                dtype=np.float32)
        self.spec = type("Spec", (), {"max_episode_steps": 200})()
        self.rng = np.random.default_rng()
        self.theta = 0.0
        self.speed = 0.0

    def _observation(self):
        return np.array([np.cos(self.theta), np.sin(self.theta), self.speed],
                        dtype=np.float32)

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.theta = self.rng.uniform(-np.pi, np.pi)
        self.speed = self.rng.uniform(-1.0, 1.0)
        return self._observation(), {}

    def step(self, action):
        u = float(np.clip(action, -MAX_TORQUE, MAX_TORQUE)[0])
        angle = ((self.theta + np.pi) % (2 * np.pi)) - np.pi
        cost = angle**2 + 0.1 * self.speed**2 + 0.001 * u**2
        self.speed = np.clip(
            self.speed + (3 * self.g / 2 * np.sin(self.theta) + 3.0 * u) * DT,
            -MAX_SPEED, MAX_SPEED)
        self.theta = self.theta + self.speed * DT
        return self._observation(), -float(cost), False, False, {}


def make(**kwargs):
    return Pendulum(**kwargs)
