"""Box and Discrete spaces with Gymnasium's attributes, without gymnasium.

vantage reads spaces by their attributes (shape, dtype, low, high; n), so
environments need not import gymnasium; these are what the test
environments use instead.
"""

import numpy as np


class Box:
    def __init__(self, low, high, shape=None, dtype=np.float32):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.shape(low)
        self.shape = tuple(shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape)
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype),
                                    self.shape)


class Discrete:
    def __init__(self, n):
        self.n = int(n)
        self.shape = ()
        self.dtype = np.dtype(np.int64)


class Dict:
    def __init__(self, spaces):
        self.spaces = dict(spaces)
