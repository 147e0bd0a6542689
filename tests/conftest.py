"""Test configuration: float64 everywhere, and `tests/` importable (`reference`, `helpers`)."""

import os
import sys

import jax

jax.config.update("jax_enable_x64", True)

_TESTS = os.path.dirname(os.path.abspath(__file__))
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)
