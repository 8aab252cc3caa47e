"""Environments that break the API in one way each, for the bridge's
error messages."""

import numpy as np

from spaces import Box, Dict, Discrete
from cartpole import CartPole


def raises_in_factory():
    raise RuntimeError("no simulator licence")


class RaisesInStep(CartPole):
    def step(self, action):
        return self.fail(action)

    def fail(self, action):
        raise ValueError(f"the simulator crashed on {action}")


class HangsSometimes(CartPole):
    """A simulator that, now and then, never returns from step(): with
    probability `p` per step, drawn from the episode's own generator, so a
    hang depends on the seed as a real one depends on the state."""

    def __init__(self, p=2e-4):
        super().__init__()
        self.p = p

    def step(self, action):
        if self.rng.random() < self.p:
            import time
            while True:
                time.sleep(3600)
        return super().step(action)


class WrongShape(CartPole):
    def reset(self, seed=None, options=None):
        return np.zeros(3, dtype=np.float32), {}


class WrongDtype(CartPole):
    def reset(self, seed=None, options=None):
        return np.zeros(4, dtype=np.int64), {}


class NanObservation(CartPole):
    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        obs[1] = np.nan
        return obs, reward, terminated, truncated, info


class InfiniteReward(CartPole):
    def step(self, action):
        obs, _, terminated, truncated, info = super().step(action)
        return obs, float("inf"), terminated, truncated, info


class OldGymApi(CartPole):
    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        return obs, reward, terminated or truncated, info


class DictObservations(CartPole):
    """A Dict space whose env returns a plain array."""

    def __init__(self):
        super().__init__()
        self.observation_space = Dict({"a": Box(-1, 1, shape=(2,))})


class NestedDict(CartPole):
    def __init__(self):
        super().__init__()
        self.observation_space = Dict(
            {"a": Dict({"b": Box(-1, 1, shape=(2,))})})


def raises_in_step():
    return RaisesInStep()


def hangs_sometimes(p=2e-4):
    return HangsSometimes(p)


def wrong_shape():
    return WrongShape()


def wrong_dtype():
    return WrongDtype()


def nan_observation():
    return NanObservation()


def infinite_reward():
    return InfiniteReward()


def old_gym_api():
    return OldGymApi()


def dict_observations():
    return DictObservations()


def nested_dict():
    return NestedDict()


class Text:
    """Gymnasium's Text space as vantage sees it: no box, no choices."""

    def __init__(self, max_length):
        self.max_length = max_length
        self.dtype = str


class TextEntry(CartPole):
    def __init__(self):
        super().__init__()
        self.observation_space = Dict(
            {"joints": Box(-1, 1, shape=(2,)), "note": Text(8)})


def text_entry():
    return TextEntry()


not_callable = 3
