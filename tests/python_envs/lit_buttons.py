"""LitButtons in plain Python: a user's environment with illegal actions.

`buttons` buttons, `lit` of them lit at each step with a value in [0, 1);
pressing a lit button earns its value, an episode is `steps` presses. The
legal actions come as Gymnasium code gives them: `mask_in="info"` puts the
mask in every reset's and step's info as info["action_mask"];
`mask_in="observation"` makes the observation a Dict of "observation" and
"action_mask" (PettingZoo's convention). An unlit press raises, so a run
that finishes never pressed one. `bad_mask` breaks the mask on purpose
after `bad_after` steps ("short", "zeros", "twos", "floats", "missing")
for the bridge's error messages.
"""

import numpy as np

from spaces import Box, Dict, Discrete


class LitButtons:
    def __init__(self, buttons=8, lit=2, steps=16, mask_in="info",
                 bad_mask="", bad_after=0):
        self.buttons, self.lit, self.steps = int(buttons), int(lit), int(steps)
        self.mask_in, self.bad_mask = mask_in, bad_mask
        self.bad_after = int(bad_after)
        board = Box(np.zeros(2 * self.buttons, np.float32),
                    np.ones(2 * self.buttons, np.float32), dtype=np.float32)
        if mask_in == "observation":
            self.observation_space = Dict({
                "observation": board,
                "action_mask": Box(np.zeros(self.buttons, np.int8),
                                   np.ones(self.buttons, np.int8),
                                   dtype=np.int8)})
        else:
            self.observation_space = board
        self.action_space = Discrete(self.buttons)
        self.max_episode_steps = self.steps
        self.rng = np.random.default_rng()
        self.values = np.full(self.buttons, -1.0)
        self.t = 0
        self.total = 0

    def draw(self):
        self.values[:] = -1.0
        chosen = self.rng.choice(self.buttons, self.lit, replace=False)
        self.values[chosen] = self.rng.random(self.lit)

    def mask(self):
        mask = self.values >= 0
        if self.total >= self.bad_after:
            if self.bad_mask == "short":
                return mask[:-1]
            if self.bad_mask == "zeros":
                return np.zeros_like(mask)
            if self.bad_mask == "twos":
                return mask.astype(np.int64) * 2
            if self.bad_mask == "floats":
                return mask.astype(np.float32)
        return mask

    def observe(self):
        lit = (self.values >= 0).astype(np.float32)
        board = np.concatenate([lit, np.maximum(self.values, 0)]).astype(
            np.float32)
        info = {}
        if self.mask_in == "observation":
            return {"observation": board,
                    "action_mask": self.mask().astype(np.int8)
                    if self.bad_mask != "floats" else self.mask()}, info
        if self.mask_in == "info" and not (
                self.bad_mask == "missing" and self.total >= self.bad_after):
            info["action_mask"] = self.mask()
        return board, info

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.t = 0
        self.draw()
        return self.observe()

    def step(self, action):
        if self.values[action] < 0:
            raise ValueError(f"button {action} is not lit")
        reward = float(self.values[action])
        self.t += 1
        self.total += 1
        self.draw()
        observation, info = self.observe()
        return observation, reward, self.t == self.steps, False, info

    def get_state(self):
        return (self.rng.bit_generator.state, self.values.copy(), self.t,
                self.total)

    def set_state(self, state):
        self.rng = np.random.default_rng()
        self.rng.bit_generator.state = state[0]
        self.values = state[1].copy()
        self.t, self.total = state[2], state[3]


def make(**kwargs):
    return LitButtons(**kwargs)
