"""CartPole (Barto, Sutton and Anderson 1983) in plain Python and numpy.

The equations, constants, thresholds and episode limit of Gymnasium's
CartPole-v1: a pole on a cart pushed left or right with a force of 10 N,
Euler steps of 0.02 s, reward 1 per step, the episode terminated when the
pole leans more than 12 degrees or the cart leaves [-2.4, 2.4], truncated
after 500 steps.
"""

import math

import numpy as np

from spaces import Box, Discrete

GRAVITY = 9.8
MASS_CART = 1.0
MASS_POLE = 0.1
TOTAL_MASS = MASS_CART + MASS_POLE
HALF_LENGTH = 0.5
POLE_MASS_LENGTH = MASS_POLE * HALF_LENGTH
FORCE = 10.0
TAU = 0.02
THETA_LIMIT = 12 * 2 * math.pi / 360
X_LIMIT = 2.4


class CartPole:
    metadata = {"render_fps": 50}

    def __init__(self, max_episode_steps=500):
        high = np.array([X_LIMIT * 2, np.finfo(np.float32).max,
                         THETA_LIMIT * 2, np.finfo(np.float32).max],
                        dtype=np.float32)
        self.observation_space = Box(-high, high, dtype=np.float32)
        self.action_space = Discrete(2)
        self.max_episode_steps = max_episode_steps
        self.rng = np.random.default_rng()
        self.state = np.zeros(4)
        self.steps = 0

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.state = self.rng.uniform(-0.05, 0.05, size=4)
        self.steps = 0
        return self.state.astype(np.float32), {}

    def step(self, action):
        if action not in (0, 1):
            raise ValueError(f"action {action!r} is not 0 or 1")
        x, x_dot, theta, theta_dot = self.state
        force = FORCE if action == 1 else -FORCE
        cos, sin = math.cos(theta), math.sin(theta)
        temp = (force + POLE_MASS_LENGTH * theta_dot**2 * sin) / TOTAL_MASS
        theta_acc = (GRAVITY * sin - cos * temp) / (
            HALF_LENGTH * (4.0 / 3.0 - MASS_POLE * cos**2 / TOTAL_MASS))
        x_acc = temp - POLE_MASS_LENGTH * theta_acc * cos / TOTAL_MASS
        x += TAU * x_dot
        x_dot += TAU * x_acc
        theta += TAU * theta_dot
        theta_dot += TAU * theta_acc
        self.state = np.array([x, x_dot, theta, theta_dot])
        self.steps += 1
        terminated = bool(abs(x) > X_LIMIT or abs(theta) > THETA_LIMIT)
        truncated = self.steps >= self.max_episode_steps
        return self.state.astype(np.float32), 1.0, terminated, truncated, {}

    # Exact resume: everything later steps depend on.
    def get_state(self):
        return (self.state.copy(), self.steps, self.rng.bit_generator.state)

    def set_state(self, state):
        self.state, self.steps, rng_state = state
        self.state = self.state.copy()
        self.rng = np.random.default_rng()
        self.rng.bit_generator.state = rng_state

    def render(self):
        image = np.full((60, 120, 3), 255, dtype=np.uint8)
        cart = int((self.state[0] + X_LIMIT) / (2 * X_LIMIT) * 119)
        image[40:46, max(cart - 6, 0):cart + 6] = (40, 40, 40)
        for r in range(30):
            px = cart + int(r * math.sin(self.state[2]))
            py = 40 - int(r * math.cos(self.state[2]))
            if 0 <= px < 120 and 0 <= py < 60:
                image[py, px] = (200, 80, 40)
        return image

    def close(self):
        pass


def make(**kwargs):
    return CartPole(**kwargs)
