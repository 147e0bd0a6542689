"""Test configuration: float64 everywhere, and `tests/` importable (`reference`, `helpers`).

- XLA compiles without LLVM's optimisation passes (`--xla_backend_optimization_level=0`,
  unless `XLA_FLAGS` is already set): compiling, not running, is what the suite spends its
  time on (about a third less wall time measured). Results agree with the optimised build
  to rounding (LLVM's contraction of multiply-adds differs), so a test that compares two
  processes bit for bit gives both the same flags (test_batch.py).
- Strict about shapes: implicit rank promotion raises (`jax_numpy_rank_promotion`), so a
  broadcast that was not meant fails here. Dtype promotion stays standard: strict promotion
  fails inside optax's L-BFGS, whose counters mix int32 and int64 under float64.
- Hypothesis draws new examples on every run here, so that the fuzz tests keep searching;
  `.ci/run` sets `HYPOTHESIS_PROFILE=ci` (`derandomize`: the same examples on every run),
  so that a landing does not depend on the draw. A failure found by chance locally becomes
  an `@example` of its test.
- JAX's persistent compilation cache on, as a user turns it on (`jaximpact.enable_cache()`;
  the library itself changes no JAX setting): compiled programs are reused between runs.
- The command line's progress reports (on stderr, also when it is not a terminal) are turned
  off for the tests, which check stderr line by line; tests of the progress turn it on.
"""

import os
import sys

os.environ.setdefault("XLA_FLAGS", "--xla_backend_optimization_level=0")
os.environ.setdefault("JAXIMPACT_PROGRESS", "off")

import jax  # noqa: E402
from hypothesis import settings  # noqa: E402

import jaximpact  # noqa: E402

settings.register_profile("ci", derandomize=True, database=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_numpy_rank_promotion", "raise")
jaximpact.enable_cache()

_TESTS = os.path.dirname(os.path.abspath(__file__))
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)
