"""A stand-in for the gymnasium package (which Debian does not ship): only
make(), over the test tree's CartPole, so `--env=gym:ID` is tested."""

import cartpole
import pendulum

_REGISTRY = {"CartPole-v1": cartpole.make, "Pendulum-v1": pendulum.make}


def make(env_id, **kwargs):
    if env_id not in _REGISTRY:
        raise KeyError(f"Environment {env_id} doesn't exist")
    return _REGISTRY[env_id](**kwargs)
