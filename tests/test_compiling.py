"""The quick compile of the library's short programs (`jaximpact/_compiling.py`)."""

import jax.numpy as jnp
import numpy as np
import pytest

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


def test_an_optimised_program_states_xla_s_default_level():
    """`optimised=True` (`fit_oblique`'s program, which runs for seconds) compiles at XLA's
    default level 3 stated, whatever `XLA_FLAGS` sets for the process (the suite's level 0,
    under which a Chung & Ooi fit ran 2-4x slower); a program is not brief and optimised."""
    assert _compiling.quick_options(optimised=True) == {
        "xla_cpu_use_fusion_emitters": False,
        "xla_backend_optimization_level": 3,
    }
    assert _compiling.quick_jit(lambda x: 2 * x, optimised=True)(jnp.asarray(1.5)) == 3.0
    with pytest.raises(ValueError, match="brief or optimised"):
        _compiling.quick_options(brief=True, optimised=True)
