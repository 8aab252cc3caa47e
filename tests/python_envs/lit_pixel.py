"""A Dict observation in plain Python: a camera image and a vector.

Each step shows a `size` x `size` single-channel uint8 image ("camera")
with one lit pixel (255) in a random row and column, and a vector
("mirror") of two values, one-hot: whether to mirror. The action names a
column: the lit pixel's, or its mirror image's (size - 1 - column) when
mirror is on. The right column earns 1, any other 0; an episode is
`steps` steps. Neither entry alone says the answer: a uniformly random
policy earns steps / size, one reading both `steps`. With `tuple=1` the
space is a Tuple of the two instead of a Dict.
"""

import numpy as np

from spaces import Box, Dict, Discrete


class Tuple:
    def __init__(self, spaces):
        self.spaces = tuple(spaces)


class LitPixel:
    def __init__(self, size=5, steps=8, tuple=0):
        self.size, self.steps, self.tuple = int(size), int(steps), int(tuple)
        camera = Box(0, 255, shape=(self.size, self.size, 1), dtype=np.uint8)
        mirror = Box(0.0, 1.0, shape=(2,), dtype=np.float32)
        self.observation_space = (Tuple([camera, mirror]) if self.tuple else
                                  Dict({"camera": camera, "mirror": mirror}))
        self.action_space = Discrete(self.size)
        self.max_episode_steps = self.steps
        self.rng = np.random.default_rng()
        self.row = self.column = self.mirror = 0
        self.t = 0

    def draw(self):
        self.row = int(self.rng.integers(self.size))
        self.column = int(self.rng.integers(self.size))
        self.mirror = int(self.rng.integers(2))

    def observe(self):
        camera = np.zeros((self.size, self.size, 1), np.uint8)
        camera[self.row, self.column, 0] = 255
        mirror = np.eye(2, dtype=np.float32)[self.mirror]
        if self.tuple:
            return (camera, mirror)
        return {"camera": camera, "mirror": mirror}

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.t = 0
        self.draw()
        return self.observe(), {}

    def step(self, action):
        answer = self.size - 1 - self.column if self.mirror else self.column
        reward = 1.0 if int(action) == answer else 0.0
        self.t += 1
        self.draw()
        return self.observe(), reward, self.t == self.steps, False, {}

    def get_state(self):
        return (self.rng.bit_generator.state, self.row, self.column,
                self.mirror, self.t)

    def set_state(self, state):
        self.rng = np.random.default_rng()
        self.rng.bit_generator.state = state[0]
        self.row, self.column, self.mirror, self.t = state[1:]


def make(**kwargs):
    return LitPixel(**kwargs)
