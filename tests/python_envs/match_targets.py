"""Several discrete choices at once, in plain Python: a MultiDiscrete (or
MultiBinary) action space.

Each step shows one target per action value (one-hot, `nvec[i]` wide, or a
bit for MultiBinary); the reward is the fraction of the action's values
that match their targets, and an episode is `steps` steps. A uniformly
random policy earns steps * mean(1 / nvec) (MultiBinary: steps / 2), one
that reads the targets `steps`.
"""

import numpy as np

from spaces import Box


class MultiDiscrete:
    def __init__(self, nvec):
        self.nvec = np.asarray(nvec, dtype=np.int64)
        self.shape = self.nvec.shape
        self.dtype = np.dtype(np.int64)


class MultiBinary:
    def __init__(self, n):
        self.n = int(n)
        self.shape = (self.n,)
        self.dtype = np.dtype(np.int8)


class MatchTargets:
    def __init__(self, nvec=(3, 4, 5), binary=0, steps=16):
        self.binary = int(binary)
        self.nvec = [2] * self.binary if self.binary else [int(n) for n in nvec]
        self.steps = int(steps)
        size = self.binary if self.binary else sum(self.nvec)
        self.observation_space = Box(np.zeros(size, np.float32),
                                     np.ones(size, np.float32),
                                     dtype=np.float32)
        self.action_space = (MultiBinary(self.binary) if self.binary else
                             MultiDiscrete(self.nvec))
        self.max_episode_steps = self.steps
        self.rng = np.random.default_rng()
        self.targets = np.zeros(len(self.nvec), np.int64)
        self.t = 0

    def observe(self):
        if self.binary:
            return self.targets.astype(np.float32)
        parts = [np.eye(n, dtype=np.float32)[target]
                 for n, target in zip(self.nvec, self.targets)]
        return np.concatenate(parts)

    def draw(self):
        self.targets = np.array([self.rng.integers(n) for n in self.nvec])

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.t = 0
        self.draw()
        return self.observe(), {}

    def step(self, action):
        action = np.asarray(action)
        if action.shape != (len(self.nvec),):
            raise ValueError(f"an action of shape {action.shape}")
        if self.binary and action.dtype != np.int8:
            raise ValueError(f"a MultiBinary action of dtype {action.dtype}")
        reward = float(np.mean(action == self.targets))
        self.t += 1
        self.draw()
        return self.observe(), reward, self.t == self.steps, False, {}

    def get_state(self):
        return self.rng.bit_generator.state, self.targets.copy(), self.t

    def set_state(self, state):
        self.rng = np.random.default_rng()
        self.rng.bit_generator.state = state[0]
        self.targets, self.t = state[1].copy(), state[2]


def make(**kwargs):
    return MatchTargets(**kwargs)
