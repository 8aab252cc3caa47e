"""A memory task in plain Python, one frame at a time: a user's own
partially observable environment.

The first frame of an episode shows one of `cues` cues (one-hot), `delay`
blank frames follow, then a frame that asks for the cue, the same whatever
it was. Naming the cue at that frame earns 1 and ends the episode; any
other action earns 0 and ends it. Actions before it do nothing. A policy
that sees only the current frame is right 1 time in `cues`.
"""

import numpy as np

from spaces import Box, Discrete


class CueRecall:
    def __init__(self, cues=4, delay=10):
        self.cues = int(cues)
        self.delay = int(delay)
        size = self.cues + 2  # the one-hot cue, "cue shown", "recall now"
        self.observation_space = Box(np.zeros(size, np.float32),
                                     np.ones(size, np.float32),
                                     dtype=np.float32)
        self.action_space = Discrete(self.cues)
        self.max_episode_steps = self.delay + 2
        self.rng = np.random.default_rng()
        self.cue = 0
        self.t = 0

    def frame(self):
        frame = np.zeros(self.cues + 2, np.float32)
        if self.t == 0:
            frame[self.cue] = 1.0
            frame[self.cues] = 1.0
        elif self.t == self.delay + 1:
            frame[self.cues + 1] = 1.0
        return frame

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.cue = int(self.rng.integers(self.cues))
        self.t = 0
        return self.frame(), {}

    def step(self, action):
        if self.t == self.delay + 1:
            reward = 1.0 if int(action) == self.cue else 0.0
            return self.frame(), reward, True, False, {}
        self.t += 1
        return self.frame(), 0.0, False, False, {}

    def close(self):
        pass


def make(**kwargs):
    return CueRecall(**kwargs)
