"""A uint8 image environment: a dot on a 10x10 RGB grid moved by four
actions toward a fixed corner; reward 1 on reaching it (terminated), -0.01
per step otherwise, 50 steps at most."""

import numpy as np

from spaces import Box, Discrete

SIZE = 10
MOVES = [(-1, 0), (1, 0), (0, -1), (0, 1)]


class DotToCorner:
    def __init__(self):
        self.observation_space = Box(0, 255, shape=(SIZE, SIZE, 3),
                                     dtype=np.uint8)
        self.action_space = Discrete(4)
        self.max_episode_steps = 50
        self.rng = np.random.default_rng()
        self.position = [0, 0]

    def _observation(self):
        image = np.zeros((SIZE, SIZE, 3), dtype=np.uint8)
        image[SIZE - 1, SIZE - 1, 1] = 255  # the corner, green
        image[self.position[0], self.position[1], 0] = 255  # the dot, red
        return image

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.position = [int(v) for v in self.rng.integers(0, SIZE - 1, 2)]
        return self._observation(), {}

    def step(self, action):
        dy, dx = MOVES[action]
        self.position = [min(max(self.position[0] + dy, 0), SIZE - 1),
                         min(max(self.position[1] + dx, 0), SIZE - 1)]
        done = self.position == [SIZE - 1, SIZE - 1]
        return self._observation(), 1.0 if done else -0.01, done, False, {}


def make():
    return DotToCorner()
