"""The user's own law: `custom_law(fn, **params)` wraps a pure JAX function
`fn(x, v, params) -> F`; `load_law_function` reads it from a file, `FILE.py:NAME`."""

from collections.abc import Callable
from pathlib import Path
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import check_values
from .base import AbstractLaw, LawSpec
from .clamps import unclamped
from .dynamics import scaled_dynamics
from .fast_powers import fast_powers
from .parameters import as_arrays


class CustomLaw(AbstractLaw):
    """A user's law `F = fn(x, v, params)` in SI units (N), built by `custom_law`."""

    fn: Callable = eqx.field(static=True)
    params: dict[str, Array]
    name: str = eqx.field(static=True, default="custom")
    has_state: ClassVar[bool] = False

    @property
    def spec(self) -> LawSpec | None:
        """A user's law has no row of the law table."""
        return None

    def replace(self, **params):
        self._refuse_unknown(params, "this custom law")
        return CustomLaw(self.fn, {**self.params, **_finite_arrays(params)}, self.name)

    def dynamics(self, *, m, v0, g):
        return scaled_dynamics(self, m=m, v0=v0, g=g)

    def force(self, x, v, **_):
        """Contact force (N) at penetration `x` (m) and velocity `v` (m/s); 0 outside the
        surface (`x < 0`).

        The user's function is only ever called inside the surface: at `x` itself where
        `x > 0`, at the smallest positive float where `0 <= x` is smaller (its limit at
        first touch, e.g. `b v` for `c x + b v`), and below the surface the force is 0 with
        gradient 0. So `x**1.5`, `jnp.sqrt(x)` or `jnp.power(x, n)` need no guard: neither
        the value nor the gradient is ever NaN. A constant power that is a multiple of 1/2
        (`x**1.5`, `jnp.power(x, 2.5)`) is evaluated as `x * sqrt(x)` and multiplies,
        10x cheaper than `pow` and within a few ulps of it (`fast_powers`)."""
        return _inside_surface(fast_powers(self.fn), x, v, self.params)

    def edge_force(self, x, v):
        """The force whose first zero inside the surface ends contact under the force
        criterion (N): the law's own, or, where the law clamps its result at zero
        (`jnp.maximum(F, 0)`, `jnp.clip(F, 0, None)`, `jax.nn.relu(F)`,
        `jnp.where(F > 0, F, 0)`), the `F` before the clamp (`clamps.unclamped`). The
        clamped force reaches zero with a flat tail that no root finder can place; `F`
        crosses zero at the same instant, transversally. The motion is always integrated
        with the law as written (`force`)."""
        peeled = unclamped(self.fn, self.params)
        if peeled is None:
            return self.force(x, v)
        return _inside_surface(fast_powers(peeled), x, v, self.params)


def _inside_surface(fn, x, v, params):
    """`fn(x, v, params)` evaluated inside the surface only (see `CustomLaw.force`)."""
    x = jnp.asarray(x, dtype=float)
    v = jnp.asarray(v, dtype=float)
    tiny = jnp.finfo(x.dtype).tiny
    inside = jnp.where(x > tiny, x, tiny)
    return jnp.where(x >= 0, fn(inside, v, params), 0.0)


def custom_law(fn: Callable, **params) -> CustomLaw:
    """Wrap a user's force law `fn(x, v, params) -> F` (SI units, N, positive pushing out).

    `fn` must be a pure JAX function of the penetration `x` (m), the velocity `v` (m/s)
    and the dict `params`, written as force laws are written: `x**1.5`, `jnp.sqrt(x)`,
    `jnp.power(x, n)` need no guard, since the library only calls `fn` with `x > 0` (the
    force is 0 outside the surface; `CustomLaw.force`). Contact ends where the force
    returns to zero inside the surface, or at `x = 0` for a force that only vanishes there
    (both separation criteria then agree). A clamp that keeps the surface from pulling,
    `jnp.maximum(F, 0)` (or `jnp.clip`, `jax.nn.relu`, `jnp.where(F > 0, F, 0)`), is
    integrated as written, and contact ends where the clamped force reaches zero.

    It goes wherever a law of the table goes, files included: `batch_file(...)` and
    `impact_batch(..., out=)` take it (its parameters are the values every row takes
    unless a column gives them; a resume checks the function's name, file and code and the
    parameters). On the command line, `--law FILE.py:NAME --param c=2e6 ...` is
    `custom_law(NAME, c=2e6, ...)` for the function `NAME(x, v, params)` of a Python file,
    named `FILE.py:NAME` in the output.

    **Example**:
    `custom_law(lambda x, v, p: p["c"] * x**1.5 * (1 + p["a"] * v), c=2e6, a=0.2)`.
    """
    if not callable(fn):
        raise ValueError("custom_law needs a function f(x, v, params) as its first argument")
    if not params:
        raise ValueError("custom_law needs the law's parameters as keywords, e.g. k=2e6")
    return CustomLaw(fn, _finite_arrays(params))


def _finite_arrays(params):
    """The parameters as arrays, each finite (any sign: the user's law decides)."""
    return {
        key: check_values(value, _never, f"custom law: parameter {key} must be a finite number")
        for key, value in as_arrays(params).items()
    }


def _never(array):
    return np.zeros(np.shape(array), bool)


# ------------------------------------------------------------ a user's law from a file


class LawFileError(ValueError):
    """A user's law `FILE.py:NAME` that cannot be loaded (`load_law_function`): the file
    missing, not Python, raising on import, or without a function NAME. Its message is the
    whole one line (a reader that adds its own context to other `ValueError`s leaves it)."""


_LOADED: dict = {}  # (file, SHA-256 of its bytes) -> its module: a file loaded once


def load_law_function(text: str):
    """The function NAME of the file FILE.py of `--law FILE.py:NAME`, the file imported once
    per content (`importlib`); one-line `LawFileError`s for a name that is not `FILE.py:NAME`, a
    file that is missing or not a .py file, a file that raises on import (which exception,
    at which line), NAME not in the file (with the callables it has) or not callable."""
    import hashlib
    import importlib.util
    import sys

    where, _, name = text.rpartition(":")
    flag = f"--law {text}"
    if not where or not name:
        raise LawFileError(
            f"{flag}: a user's law is FILE.py:NAME, the file and the name of its "
            "function NAME(x, v, params)"
        )
    path = Path(where)
    if path.suffix != ".py":
        raise LawFileError(
            f"{flag}: {where} is not a .py file; a user's law is FILE.py:NAME, a "
            "function NAME(x, v, params) in a Python file"
        )
    if not path.exists():
        raise LawFileError(f"{flag}: no such file {where}")
    if not path.is_file():
        raise LawFileError(f"{flag}: {where} is not a file")
    try:
        source = path.read_bytes()
    except OSError as error:
        raise LawFileError(f"{flag}: cannot read {where} ({error.strerror or error})") from None
    digest = hashlib.sha256(source).hexdigest()
    key = (str(path.resolve()), digest)
    module = _LOADED.get(key)
    if module is None:
        module_name = f"_jaximpact_law_{digest[:16]}"
        spec = importlib.util.spec_from_file_location(module_name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module  # as an import has it (dataclasses look it up)
        try:
            spec.loader.exec_module(module)
        except (Exception, SystemExit) as error:
            del sys.modules[module_name]
            line = line_in(error, path)
            raise LawFileError(
                f"{flag}: importing {where} raised {type(error).__name__}{line}: "
                f"{first_line(error)}"
            ) from None
        _LOADED[key] = module
    if not hasattr(module, name):
        from .._choices import nearest_names

        own = [
            k
            for k, v in vars(module).items()
            if callable(v)
            and not k.startswith("_")
            and getattr(v, "__module__", None) == module.__name__
        ]
        near = nearest_names(name, own)
        hint = f" (did you mean {' or '.join(near)}?)" if near else ""
        has = f"its callables: {', '.join(own)}" if own else "it defines no function"
        raise LawFileError(f"{flag}: {where} has no {name!r}{hint}; {has}")
    fn = getattr(module, name)
    if not callable(fn):
        raise LawFileError(
            f"{flag}: {name} in {where} is a {type(fn).__name__}, not a function "
            f"{name}(x, v, params)"
        )
    return fn


def first_line(error) -> str:
    text = str(error).strip()
    if isinstance(error, SyntaxError):  # its str holds the file and line: said apart
        text = error.msg or text
    return (text.splitlines() or [""])[0] or "(no message)"


def line_in(error, where) -> str:
    """` at line N` of the user's file (`where`: its path, or a function defined in it)
    where `error` was raised, or `""`."""
    import traceback

    if isinstance(where, (str, Path)):
        file = str(Path(where).resolve())
    else:
        import inspect

        try:
            file = str(Path(inspect.getsourcefile(inspect.unwrap(where))).resolve())
        except TypeError:
            return ""
    if isinstance(error, SyntaxError) and error.filename is not None:
        if str(Path(error.filename).resolve()) == file and error.lineno:
            return f" at line {error.lineno}"
    frames = [
        f
        for f in traceback.extract_tb(error.__traceback__)
        if str(Path(f.filename).resolve()) == file
    ]
    return f" at line {frames[-1].lineno}" if frames else ""
