"""The quick compile of the library's short programs (`jaximpact/_compiling.py`)."""

import jax.numpy as jnp
import numpy as np

from jaximpact import _compiling


def test_quick_jit_gives_what_the_function_gives():
    f = _compiling.quick_jit(lambda x, n: jnp.sin(x) * n)
    assert f(jnp.asarray(1.0), 3) == np.sin(1.0) * 3
    assert f(jnp.asarray(2.0), 3) == np.sin(2.0) * 3  # the same program, new numbers


def test_an_option_this_xla_does_not_know_falls_back_to_its_defaults(monkeypatch):
    monkeypatch.setattr(_compiling, "QUICK_COMPILE", {"xla_no_such_option_anywhere": True})
    _compiling.quick_options.cache_clear()
    try:
        assert _compiling.quick_options() == {}
        assert _compiling.quick_jit(lambda x: 2 * x)(jnp.asarray(1.5)) == 3.0
    finally:
        monkeypatch.undo()
        _compiling.quick_options.cache_clear()
    assert _compiling.quick_options() == {"xla_cpu_use_fusion_emitters": False}
