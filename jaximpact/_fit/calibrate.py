"""Fitting a law's parameters to measured restitution and contact duration."""

import dataclasses
import functools
import warnings
from typing import NamedTuple

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
import optimistix as optx
from jaxtyping import Array

from .._checks import MemberChecks, check_scale, is_traced
from .._compiling import quick_jit
from .._curves.gravity import WithGravity
from .._curves.similarity import beta_for_restitution, curve_values
from .._curves.store import curves_for
from .._format import (
    format_fields,
    format_number,
    format_value,
    jsonable,
)
from .._laws import AbstractLaw, damping_parameter, shape_of, stiffness_parameter
from .._laws.listing import law_units
from .._least_squares import LeastSquares, levenberg_marquardt
from .._solve.impact import ImpactOptions, solve_impact
from .._solve.options import (
    FIT_DECIDES,
    Path,
    SolveOptions,
    choose_path,
    is_no_gravity,
    make_options,
    solve_options,
    with_defaults,
)
from .._status import Status
from .._stored import stored_jit
from .._xla_log import quietly_compiled
from .forward_jacobian import rows_value_and_jacobian, value_and_jacobian, with_forward_jacobian
from .parameters import default_free, law_with, to_unbounded
from .restitution_tables import restitution_table

OPTIMIZERS = ("auto", "lbfgs", "lm")


class Fit(eqx.Module):
    """A calibrated law and how well it reproduces the measurements.

    - `law`, `params`: the fitted law and its parameters (SI units).
    - `e`, `T`: predicted restitution and contact duration (s) at every row's `v0`.
    - `m` (kg), `x_max` (m), `F_max` (N): the mass fitted for, and the largest penetration
      and contact force the fitted law implies at every row's `v0`: a sanity echo (grams
      typed as kilograms give a force a thousand times too large).
    - `residuals`: weighted residuals, `(e_fit - e)/sigma_e` then `(T_fit - T)/sigma_T`
      (without sigmas: `e_fit - e` and `(T_fit - T)/T`); 0 for a row without `T`.
    - `loss`: half the sum of squared residuals; `history`: the loss at each iteration.
    - `converged`: the optimiser stopped at a minimum of the loss (gradient or steps below
      `tol`, or the loss at the noise floor of the impact solves) and every fitted impact
      separates; at one speed with `e` and `T` (solved on the curves, no iteration) the
      equations were solved to 1e-6. It says nothing of how well the law fits the data:
    - `reproduces`: every residual is within `target_tol` (default 1e-6 without sigmas,
      i.e. the data to numerical precision, as synthetic data are: real data give `False`;
      3 with sigmas, every point within three standard deviations).
    - Goodness of fit: `n_data` (measured values: every `e` and every `T` given), `dof`
      (`n_data` minus the free parameters), `chi2` (sum of squared residuals: with sigmas
      the sum of squared normalised residuals, a chi-square with `dof` degrees of freedom),
      `reduced_chi2` (`chi2 / dof`, about 1 for a law that fits within the sigmas; NaN
      without sigmas or without degrees of freedom) and its `p_value`, and, with or
      without sigmas, `rms_e` (RMS of `e_fit - e`) and `rms_T` (RMS of `(T_fit - T)/T`,
      relative).
    - `iterations`; `stderr`: standard errors of the free parameters from the Jacobian,
      scaled by the sigmas when given, else by the residuals' own scatter (`chi2 / dof`
      stands for the variance of every residual, as `fit_bounces` does); without sigmas
      and without a degree of freedom left (as many data as free parameters) `None` (NaN
      inside `jit` or `vmap`).
    - `undetermined`: free parameters these data cannot fix (fewer data than free
      parameters, or `e` alone for a one-group law, which fixes only the group `beta`
      that stiffness and damping make together); their values are not estimates. A
      warning says so when the fit is not traced.
    - `notes`: what the data determined where that is not every parameter, e.g. with `e`
      alone "e determines beta = ...; c held at its start value" (concrete fits only).
    """

    law: AbstractLaw
    params: dict[str, Array]
    v0: Array
    e: Array
    T: Array
    e_target: Array
    T_target: Array
    residuals: Array
    loss: Array
    converged: Array
    iterations: Array
    history: Array
    stderr: dict[str, Array] | None
    free: tuple[str, ...] = eqx.field(static=True)
    optimizer: str = eqx.field(static=True)
    undetermined: tuple[str, ...] = eqx.field(static=True, default=())
    m: Array | None = None
    x_max: Array | None = None
    F_max: Array | None = None
    reproduces: Array | None = None
    target_tol: Array | None = None
    n_data: Array | None = None
    weighted: bool = eqx.field(static=True, default=False)
    notes: tuple[str, ...] = eqx.field(static=True, default=())
    # what the fit was made of, so that `posterior` rebuilds the same forward model: the
    # sigmas as given (None: not given), gravity g (m/s^2), and the compiled fit's options
    # (free parameters, separation, tolerance, curves or closed form)
    sigma_e: Array | None = None
    sigma_T: Array | None = None
    g: Array | float = 0.0
    setup: eqx.Module | None = None

    # --------------------------------------------------------------- goodness of fit

    @property
    def dof(self) -> Array:
        """Degrees of freedom: measured values minus free parameters."""
        return self.n_data - len(self.free)

    @property
    def chi2(self) -> Array:
        """Sum of squared residuals (with sigmas: of normalised residuals, a chi-square)."""
        return jnp.sum(jnp.square(self.residuals), axis=-1)

    @property
    def reduced_chi2(self) -> Array:
        """`chi2 / dof` with sigmas (about 1 for a law that fits within them); NaN without
        sigmas (the residuals then have no scale) or without a degree of freedom."""
        dof = self.dof
        ok = self.weighted & (dof > 0)
        return jnp.where(ok, self.chi2 / jnp.where(dof > 0, dof, 1), jnp.nan)

    @property
    def p_value(self) -> Array:
        """Probability of a chi-square at least this large if the law were right and the
        sigmas the data's true scatter (NaN where `reduced_chi2` is)."""
        reduced = self.reduced_chi2
        if not is_traced(reduced) and np.all(np.isnan(reduced)):
            # none to compute (no sigmas or no degree of freedom): the incomplete gamma
            # function is not compiled for nothing (0.7 s of a 4.8 s `jaximpact calibrate`)
            return jnp.asarray(np.full(np.shape(reduced), np.nan))
        dof = jnp.where(self.dof > 0, self.dof, 1).astype(float)
        p = jax.scipy.special.gammaincc(dof / 2.0, self.chi2 / 2.0)
        return jnp.where(jnp.isnan(reduced), jnp.nan, p)

    @property
    def rms_e(self) -> Array:
        """RMS of `e_fit - e` over the rows (NaN where e was not measured)."""
        return jnp.sqrt(jnp.mean(jnp.square(self.e - self.e_target), axis=-1))

    @property
    def rms_T(self) -> Array:
        """RMS of `(T_fit - T)/T` over the rows with a measured T (relative; NaN if none)."""
        known = jnp.isfinite(self.T_target)
        target = jnp.where(known, self.T_target, 1.0)
        relative = jnp.where(known, (self.T - target) / target, 0.0)
        count = jnp.sum(known, axis=-1)
        mean = jnp.sum(jnp.square(relative), axis=-1) / jnp.where(count > 0, count, 1)
        return jnp.where(count > 0, jnp.sqrt(mean), jnp.nan)

    @property
    def max_residual(self) -> Array:
        """The largest `|residual|` (what `target_tol` bounds)."""
        return jnp.max(jnp.abs(self.residuals), axis=-1)

    def summary(self) -> str:
        """The fit as text: each parameter with its unit (and standard error, or `fixed`,
        or `undetermined`), whether the optimiser converged, how well the law fits
        (reduced chi-square with sigmas, RMS residuals without) and whether it reproduces
        the data, then e and T predicted beside their targets at each speed, with the
        penetration and force they imply, and the notes; inside `jit` the shapes
        (`traced f64[]`)."""
        units = law_units(self.law)
        order = [k for k in self.law.parameters if k in self.params]  # the row's order
        order += [k for k in self.params if k not in order]  # not jit's
        rows = []
        for name in order:
            value = self.params[name]
            unit = units.get(name, "")
            text = format_value(value, unit)
            if name not in self.free:
                text += " (fixed)"
            elif name in self.undetermined:
                text += " (undetermined by these data)"
            elif self.stderr is not None and name in self.stderr:
                text += f" ± {format_value(self.stderr[name], unit)}"
            rows.append((name, text))
        one = _is_one_concrete_fit(self)
        rows += [
            ("converged", converged_text(self) if one else format_value(self.converged, None)),
            ("iterations", format_value(self.iterations, None)),
        ]
        if self.n_data is not None:
            rows.append(("fit", goodness_text(self) if one else format_value(self.chi2)))
        if self.reproduces is not None:
            shown = reproduces_text(self) if one else format_value(self.reproduces, None)
            rows.append(("reproduces", shown))
        rows += [
            ("loss", format_value(self.loss)),
            ("v0", format_value(self.v0, "m/s")),
            ("e", f"{format_value(self.e)} ({_target_text(self.e_target, '')})"),
            ("T", f"{format_value(self.T, 's')} ({_target_text(self.T_target, 's')})"),
        ]
        if self.m is not None and self.x_max is not None:
            rows += [
                ("m", format_value(self.m, "kg")),
                ("x_max", format_value(self.x_max, "m") + " (implied by the fit)"),
                ("F_max", format_value(self.F_max, "N") + " (implied by the fit)"),
            ]
        name = self.law.name
        text = format_fields(f"Fit of {name} ({self.optimizer}; SI units)", rows)
        return "\n".join([text, *(f"  note: {note}" for note in self.notes)])

    def to_dict(self) -> dict:
        """The fit as plain numbers and lists (SI units), NaN as None: `law` (name and
        parameters), `params`, `stderr`, `free`, `undetermined`, `converged` (the
        optimiser), `reproduces`, `target_tol`, the goodness of fit (`n_data`, `dof`,
        `chi2`, `reduced_chi2`, `p_value`, `rms_e`, `rms_T`, `weighted`), `iterations`,
        `loss`, `history`, per speed `v0`, `e`, `T`, `e_target`, `T_target`, `x_max`,
        `F_max`, `residuals`, the mass `m`, and the `notes`. Concrete fits only (not
        inside `jit`)."""
        names = (
            "params",
            "stderr",
            "converged",
            "reproduces",
            "target_tol",
            "iterations",
            "loss",
            "history",
            "m",
            "v0",
            "e",
            "T",
            "e_target",
            "T_target",
            "x_max",
            "F_max",
            "residuals",
        )
        out = {k: jsonable(getattr(self, k)) for k in names}
        if self.n_data is not None:
            out.update(
                {
                    k: jsonable(getattr(self, k))
                    for k in ("n_data", "dof", "chi2", "reduced_chi2", "p_value", "rms_e", "rms_T")
                }
            )
        law = {"name": self.law.name}
        law["parameters"] = out["params"]
        return {
            "law": law,
            **out,
            "g": jsonable(self.g),
            "free": list(self.free),
            "optimizer": self.optimizer,
            "undetermined": list(self.undetermined),
            "weighted": self.weighted,
            "notes": list(self.notes),
        }

    @classmethod
    def from_dict(cls, data: dict, *, law=None) -> "Fit":
        """The fit that `to_dict()` wrote (`Fit.from_dict(fit.to_dict()).to_dict()` is
        `fit.to_dict()`), or the JSON of `jaximpact calibrate --json` (one law), which
        names the law by `law` with its `params` and gives each speed as one of `rows`
        (`v0`, the measured `e` and `T`, `e_fit`, `T_fit`, `x_max`, `F_max`). `law`: where
        a name cannot rebuild the law (a user's own, `custom_law`), the law, or a function
        that builds it from the parameters (a dict of numbers, checked first).

        Its numbers and words come back (`summary()`, the goodness of fit, `to_dict()`);
        what a dict does not hold is None (`setup`, the sigmas: `posterior` needs the fit
        itself), a per-speed value it lacks NaN. A one-line `ValueError` for a dict that is
        no fit: no law name or no parameters, a law or a parameter the law table does not
        have, a parameter that is not a finite number, a mass (kg) or a speed (m/s) that is
        not a number > 0.

        **Example**: `Fit.from_dict(json.loads(text)).law`.
        """
        import math

        from .._laws import LAWS, law as named_law

        def number(value):
            return isinstance(value, (int, float)) and not isinstance(value, bool)

        given = data.get("law")
        name = given.get("name") if isinstance(given, dict) else given
        if not isinstance(name, str):
            raise ValueError(
                "no law name ('law'): is it a Fit.to_dict(), or the output of 'jaximpact "
                "calibrate --json'?"
            )
        params = data.get("params", given.get("parameters") if isinstance(given, dict) else None)
        if not isinstance(params, dict) or not params:
            raise ValueError("no parameters ('params': an object NAME -> number)")
        for key, value in params.items():
            if not (number(value) and math.isfinite(value)):
                raise ValueError(f"parameter {key} = {value!r} is not a finite number")
        if law is not None and not isinstance(law, AbstractLaw):
            law = law({k: float(v) for k, v in params.items()})
        elif law is None:
            if name not in LAWS:
                raise ValueError(f"law {name!r} is not one of 'jaximpact laws' (LAW_NAMES)")
            unknown = sorted(set(params) - set(LAWS[name].parameters))
            if unknown:
                raise ValueError(f"law {name} has no parameter {', '.join(unknown)}")
            law = named_law(name, **{k: float(v) for k, v in params.items()})
        m = data.get("m")
        if m is not None and not (number(m) and math.isfinite(m) and m > 0):
            raise ValueError(f"mass m = {m!r} is not a number > 0 (kg)")
        rows = data.get("rows") if isinstance(data.get("rows"), list) else []
        rows = [row for row in rows if isinstance(row, dict)]

        def per_speed(key, in_rows):  # to_dict's list (one number: simulate's), or the rows'
            values = data[key] if key in data else [row.get(in_rows) for row in rows]
            return np.atleast_1d(np.asarray(values, dtype=float))  # null: NaN

        v0 = data["v0"] if "v0" in data else [row.get("v0") for row in rows]
        if not all(number(v) and math.isfinite(v) and v > 0 for v in np.ravel(v0)):
            raise ValueError("a speed ('v0' or 'rows'[].v0) is not a number > 0 (m/s)")

        def read(key, kind=float, where=data):  # None where not given; a null number NaN
            value = where.get(key)
            if value is None and (kind is not float or key not in where):
                return None
            return np.asarray(value, dtype=kind)

        stderr = data.get("stderr")
        return cls(
            law=law,
            params={k: np.asarray(float(v)) for k, v in params.items()},
            v0=per_speed("v0", "v0"),
            e=per_speed("e", "e_fit"),
            T=per_speed("T", "T_fit"),
            e_target=per_speed("e_target", "e"),
            T_target=per_speed("T_target", "T"),
            residuals=read("residuals"),
            loss=read("loss"),
            converged=read("converged", bool),
            iterations=read("iterations", int),
            history=read("history"),
            stderr=None if stderr is None else {k: read(k, where=stderr) for k in stderr},
            free=tuple(data.get("free", ())),
            optimizer=data.get("optimizer"),
            undetermined=tuple(data.get("undetermined", ())),
            m=None if m is None else np.asarray(float(m)),
            x_max=per_speed("x_max", "x_max"),
            F_max=per_speed("F_max", "F_max"),
            reproduces=read("reproduces", bool),
            target_tol=read("target_tol"),
            n_data=read("n_data", int),
            weighted=bool(data.get("weighted", False)),
            notes=tuple(data.get("notes", ())),
            g=float(data.get("g") or 0.0),
        )

    def __repr__(self) -> str:
        return self.summary()


def _is_one_concrete_fit(fit) -> bool:
    """A fit with numbers (not traced) for one body (not a batch from `jax.vmap`)."""
    return not is_traced(fit.loss) and np.ndim(fit.loss) == 0 and fit.n_data is not None


def converged_text(fit) -> str:
    """Whether the optimiser converged, in words (one concrete fit)."""
    if bool(fit.converged):
        if int(fit.iterations) == 0:
            return "True (solved at the start: no iteration needed)"
        return "True (the optimiser stopped at a minimum of the loss)"
    return (
        f"False (no minimum reached in {int(fit.iterations)} iterations, or an impact "
        "of the fitted law does not separate)"
    )


def goodness_text(fit) -> str:
    """How well the law fits, with what each number means (one concrete fit): reduced
    chi-square with its degrees of freedom when sigmas were given, RMS residuals in e
    and (relative) in T otherwise."""
    dof = int(fit.dof)
    parts = []
    if fit.weighted:
        chi2 = float(fit.chi2)
        if dof > 0:
            parts.append(
                f"reduced chi-square {format_number(float(fit.reduced_chi2), 3)} with {dof} "
                f"degrees of freedom (p = {format_number(float(fit.p_value), 2)}; "
                f"chi2 = {format_number(chi2, 3)}, the sum of squared normalised residuals)"
            )
        else:
            parts.append(
                f"chi2 = {format_number(chi2, 3)} (sum of squared normalised residuals) with "
                "no degree of freedom left: as many data as free parameters, the fit cannot "
                "be judged"
            )
    rms = []
    if np.any(np.isfinite(np.asarray(fit.e_target))):
        rms.append(f"RMS of e_fit - e = {format_number(float(fit.rms_e), 3)}")
    if np.isfinite(float(fit.rms_T)):
        rms.append(f"RMS of (T_fit - T)/T = {format_number(100 * float(fit.rms_T), 3)} %")
    if rms:
        text = ", ".join(rms)
        if not fit.weighted:
            text += (
                f" ({dof} degrees of freedom; no sigmas given, so no chi-square: compare "
                "with the scatter of the measurements)"
                if dof > 0
                else " (as many data as free parameters: an exact fit is expected)"
                if dof == 0
                else " (fewer data than free parameters)"
            )
        parts.append(text)
    return "; ".join(parts)


def reproduces_text(fit) -> str:
    """Whether every residual is within `target_tol`, and what that tolerance means."""
    tol = format_number(float(fit.target_tol))
    meaning = (
        f"{tol} standard deviations (the sigmas given)"
        if fit.weighted
        else f"{tol} (no sigmas: the data to numerical precision, as synthetic data are)"
    )
    if bool(fit.reproduces):
        return f"True: every residual within target_tol = {meaning}"
    largest = format_number(float(fit.max_residual), 3)
    return f"False: largest residual {largest}, target_tol = {meaning}"


def _target_text(target, unit: str) -> str:
    """`target 7.8 ms`, `not measured` where no row has one (NaN), and a short list with the
    rows that have none named so: `target [8 ms, not measured, 7.2 ms]`."""
    if is_traced(target):
        return f"target {format_value(target, unit)}"
    values = np.asarray(target)
    if not np.any(np.isfinite(values)):
        return "not measured"
    if values.ndim == 1 and values.size <= 4 and not np.all(np.isfinite(values)):
        shown = (format_value(x, unit) if np.isfinite(x) else "not measured" for x in values)
        return f"target [{', '.join(shown)}]"
    return f"target {format_value(target, unit)}"


def _as_rows(name, value, rows, allow_missing=False):
    """`value` as one entry per row: numpy for concrete inputs (no eager JAX dispatch, which
    would cost more than a fit on the curves), `jax.numpy` for traced ones."""
    if value is None:
        return None
    if isinstance(value, (list, tuple)):
        if allow_missing:
            value = [np.nan if item is None else item for item in value]
        value = np.asarray(value, dtype=float)
    xp = jnp if is_traced(value) else np
    value = xp.atleast_1d(xp.asarray(value, dtype=float))
    if value.ndim != 1:
        raise ValueError(f"{name} must be a number or a 1-D array, got shape {value.shape}")
    if rows is not None and value.shape[0] not in (1, rows):
        raise ValueError(
            f"{name} has {value.shape[0]} values but v0 has {rows}: give one per impact speed"
        )
    return xp.broadcast_to(value, (rows,)) if rows is not None else value


def check_targets(m, v0, e, T, sigma_e, sigma_T, *, sticks=False, checks=None):
    """One-line ValueErrors for impossible targets, each concrete input checked; `sticks`:
    the law can hold the body (`LawSpec.captures`), so `e = 0` is a measurement. Returns
    `(m, v0, e, T, sigma_e, sigma_T)`: a traced input (inside `jit` or `vmap`) is not
    refused but marks the member invalid in `checks` (a `MemberChecks`, whose `refuse`
    gives that fit NaN) and is replaced by a harmless value."""
    checks = MemberChecks() if checks is None else checks
    if not is_traced(m):
        if not np.all(np.asarray(m) > 0) or not np.all(np.isfinite(np.asarray(m))):
            raise ValueError(f"mass m must be a finite number > 0 kg, got {np.asarray(m)}")
    else:
        m = checks.values(m, _not_positive, "")
    if not is_traced(v0):
        if np.any(~np.isfinite(np.asarray(v0))) or np.any(np.asarray(v0) <= 0):
            raise ValueError("every impact speed v0 must be a finite number > 0 m/s")
    else:
        v0 = checks.values(v0, _not_positive, "")

    def out_of_range(a):
        return ((a < 0) if sticks else (a <= 0)) | (a > 1)

    if e is not None and not is_traced(e):
        ea = np.asarray(e)
        if np.any(np.isnan(ea)):
            raise ValueError("e contains NaN; every row needs a measured restitution")
        bad = out_of_range(ea)
        if np.any(bad):
            interval = "[0, 1] (0: stuck)" if sticks else "(0, 1]"
            raise ValueError(f"restitution e must lie in {interval}, got {ea[bad]}")
    elif e is not None:
        e = checks.values(e, out_of_range, "", harmless=0.5)
    if T is not None and not is_traced(T):
        Ta = np.asarray(T)
        if np.all(np.isnan(Ta)):
            raise ValueError("T has no value; leave T=None to fit e alone")
        if np.any(Ta[~np.isnan(Ta)] <= 0) or np.any(np.isinf(Ta)):
            raise ValueError("contact durations T must be finite and > 0 s (None: no T)")
    elif T is not None:  # NaN: a row without T, unless every row is
        wrong = jnp.all(jnp.isnan(T)) | jnp.any((T <= 0) | jnp.isinf(T))
        T = checks.mark(wrong, T, 1e-3)
    sigmas = {"sigma_e": sigma_e, "sigma_T": sigma_T}
    for name, sigma in sigmas.items():
        if sigma is not None and not is_traced(sigma):
            if np.any(~np.isfinite(np.asarray(sigma))) or np.any(np.asarray(sigma) <= 0):
                raise ValueError(f"{name} must be finite and > 0")
        elif sigma is not None:
            sigmas[name] = checks.values(sigma, _not_positive, "")
    sigma_e, sigma_T = sigmas.values()
    if e is None and T is None:
        raise ValueError("give e, T or both to calibrate against")
    # sizes float64 carries through a fit: 1e-300 kg refused as 1e300 kg is (traced: left)
    check_scale("mass m", m, "kg")
    check_scale("impact speed v0", v0, "m/s")
    if not any(is_traced(a) for a in (m, v0)):
        energy = np.asarray(m, float) * np.asarray(v0, float) ** 2
        check_scale("contact energy m v0^2", energy, "J")
    for name, value, unit in (("T", T, "s"), ("sigma_e", sigma_e, ""), ("sigma_T", sigma_T, "s")):
        if value is not None:
            check_scale(name, value, unit)
    if T is not None and not any(is_traced(a) for a in (v0, T)):
        span = np.asarray(v0) * np.asarray(T)  # the contact's reach: x_max < v0 T
        worst = int(np.nanargmax(span)) if np.any(np.isfinite(span)) else None
        if worst is not None and span[worst] > MAX_REACH:
            warnings.warn(
                f"T = {np.asarray(T)[worst]:g} s at v0 = {np.asarray(v0)[worst]:g} m/s lets "
                f"the body travel up to v0 T = {span[worst]:.3g} m into the surface: a "
                "compliant contact law is for small deformations; is T in seconds and v0 "
                "in m/s?",
                stacklevel=3,
            )
    return m, v0, e, T, sigma_e, sigma_T


def _not_positive(a):
    return a <= 0


# the reach v0 T (m) above which a target is flagged as implausible for a compliant contact
MAX_REACH = 1.0


# ------------------------------------------------------------------- initial values


def _initial_law(law, free, *, m, v0, e, T, separation):
    """Start from one dimensionless damping group: `e` sets it (through a table of the
    law's nondimensional impact), `T` then sets the time scale and so the stiffness."""
    spec = law.spec
    if spec is None or not spec.restitution_table:
        return law
    damping = spec.damping
    if damping not in free or e is None:
        return law
    if is_traced(law.params.get("n", 0.0)):
        return law
    n = float(law.params.get("n", 1.5))  # a law with an exponent parameter: one table per n
    groups, e_table, tau_table = restitution_table(spec.name, separation, n)
    # 1 - e is nearly proportional to the group at light damping: interpolate logarithms
    loss_table = np.log(np.maximum(1.0 - e_table, 1e-300))
    order = np.argsort(loss_table)  # e rises or falls with the group, depending on the law
    groups, loss_table, tau_table = groups[order], loss_table[order], tau_table[order]
    row = jnp.argsort(v0)[v0.shape[0] // 2]
    v_row, e_row = v0[row], e[row]
    loss_row = jnp.log(jnp.maximum(1.0 - e_row, 1e-300))
    log_group = jnp.interp(loss_row, loss_table, np.log(groups))
    group = jnp.exp(log_group)
    tau = jnp.interp(loss_row, loss_table, tau_table)
    if law.has_state:  # Maxwell: group b / sqrt(m c), tau = T / sqrt(m / c)
        c = law.params["c"]
        if T is not None and "c" in free:
            c = jnp.where(jnp.isfinite(T[row]), m * (tau / T[row]) ** 2, c)
        return law.replace(**({"c": c} if "c" in free else {}), b=group * jnp.sqrt(m * c))
    _, n_law, _, p, _, _ = spec.coefficients(law.params, v_row)
    c = law.params["c"]
    if T is not None and "c" in free:
        x_star = v_row * T[row] / tau
        c = jnp.where(jnp.isfinite(T[row]), m * v_row**2 / x_star ** (n_law + 1.0), c)
    x_star = (m * v_row**2 / c) ** (1.0 / (n_law + 1.0))
    b = group * m * v_row / x_star ** (p + 1.0)
    b_per_unit = spec.coefficients({**law.params, "c": c, damping: 1.0}, v_row)[2]
    return law.replace(**({"c": c} if "c" in free else {}), **{damping: b / b_per_unit})


def _start_on_curves(law, free, *, m, v0, e, T, has_T, key):
    """The start read off the curves (inside the compiled fit; the curves were loaded, or
    built, by `choose_path` before it was compiled): `beta` from `e` at the
    median speed by inverting `e(beta)`, then `T/t* = tau(beta)` gives `t*` and so the
    stiffness, and `beta` the damping (linear in the damping parameter at fixed `c`). At
    one speed with `e` and `T` this is the fit itself, to the curves' accuracy."""
    damping = damping_parameter(law)
    if damping not in free or damping == "e_nominal":
        return law
    curves = curves_for(key)
    row = jnp.argsort(v0)[v0.shape[0] // 2]
    v_row = v0[row]
    beta = beta_for_restitution(curves, e[row])
    params = dict(law.params)
    if has_T and "c" in free:
        tau = curve_values(curves, beta, (1,))[0]
        x_star = v_row * T[row] / tau
        c = m * v_row**2 / x_star ** (key.n + 1.0)
        params["c"] = jnp.where(jnp.isfinite(T[row]) & (c > 0), c, params["c"])
    unit = eqx.tree_at(lambda item: item.params, law, {**params, damping: jnp.ones_like(v_row)})
    beta_per_unit = unit.dynamics(m=m, v0=v_row, g=0.0).beta
    params[damping] = jnp.where(beta_per_unit > 0, beta / beta_per_unit, params[damping])
    return eqx.tree_at(lambda item: item.params, law, params)


# ------------------------------------------------------------------------------ the fit


class ForwardModel(NamedTuple):
    """How a fit's impacts were solved, for a caller that rebuilds its forward model
    (`_residual_function`): `separation`, the tolerance `rtol` of each solve, and the path,
    `curves` (a `CurveKey`, or a two-group table's key; None off the curves) and
    `closed_form` (the law's exact solution). `ForwardModel.of(fit.setup)` reads them off
    a fit."""

    separation: str
    rtol: float
    curves: object = None
    closed_form: bool = False

    @classmethod
    def of(cls, setup) -> "ForwardModel":
        """The forward model of a fit's `setup` (`Fit.setup`, an `_Options`)."""
        return cls(setup.separation, setup.rtol, setup.curves, setup.closed_form)


def _residual_function(law, free, model: ForwardModel, *, m, g, has_e, has_T):
    """`_residuals` of `law` with its `free` parameters, for a body of `m` (kg) under
    gravity `g` (m/s^2), with the options of a fit solved as `model` says, every other
    option at `calibrate`'s default; `has_e`, `has_T`: which residuals it returns."""
    path = Path("closed_form" if model.closed_form else "integrated", model.curves)
    solve = SolveOptions(rtol=model.rtol)
    options = _impact_options(path, solve, separation=model.separation, g=g)
    return _residuals(law, free, options, m=m, g=g, has_e=has_e, has_T=has_T)


def _impact_options(path, solve: SolveOptions, *, separation, g) -> ImpactOptions:
    """The `ImpactOptions` of a fit's solves on `path`: `solve`'s fields, at `calibrate`'s
    defaults where None (`atol` = `rtol`, `rest_tol` 1e-9, `diffrax.Tsit5()`), the peaks
    left out (the final evaluation asks for them) and diffrax's `ForwardMode` (the fit's
    Jacobian is a forward-mode one, `with_forward_jacobian`)."""
    solve = with_defaults(
        solve,
        atol=solve.rtol,
        max_steps=4096,
        tau_max=1e4,
        rest_tol=1e-9,
        solver=dfx.Tsit5(),
        adjoint=dfx.ForwardMode(),
        peaks=False,
    )
    return make_options(path, solve, separation=separation, gravity=not is_no_gravity(g))


def _residuals(law, free, options: ImpactOptions, *, m, g, has_e, has_T):
    """Weighted residuals and predictions `(e, T, status)` (with `options.peaks`, also
    `x_max` and `F_max`) of the impacts of `law` with its `free` parameters at `theta`,
    solved as `options` say: read off the universal curves (`options.similarity`), taken
    from the law's exact solution (`options.closed_form`: Kelvin-Voigt, Bingham, Maxwell),
    or integrated; differentiated in forward mode only (through `with_forward_jacobian`),
    hence the explicit `ForwardMode` adjoint."""

    predict = _predictions(law, free, options, m=m, g=g)

    def residuals(theta, data):
        fields, status = jax.vmap(lambda v: predict(theta, v))(data[0])
        e, T = fields[0], fields[1]
        return _weighted(e, T, data, has_e=has_e, has_T=has_T), (e, T, status, *fields[2:])

    return residuals


def _predictions(law, free, options: ImpactOptions, *, m, g):
    """`(theta, v0) -> ((e, T) and with `options.peaks` (x_max, F_max), status)`: one
    impact of `law` with its `free` parameters at `theta`, solved as `options` say."""

    def predict(theta, v0):
        result = solve_impact(law_with(law, free, theta), m, v0, g, None, options)
        peaks = (result.x_max, result.F_max) if options.peaks else ()
        return (result.e, result.T, *peaks), result.status

    return predict


def _weighted(e, T, data, *, has_e, has_T):
    """The residuals `(e - e_measured) / sigma_e` and `(T - T_measured) / sigma_T` (0 where
    no `T` was measured), concatenated: what a fit's least squares takes."""
    _, e_measured, T_measured, s_e, s_T = data
    parts = []
    if has_e:
        parts.append((e - e_measured) / s_e)
    if has_T:
        known = jnp.isfinite(T_measured)
        T_safe = jnp.where(known, T_measured, 1.0)
        parts.append(jnp.where(known, (T - T_safe) / s_T, 0.0))
    return jnp.concatenate(parts)


def _run_lbfgs(loss, theta0, data, optimizer, max_iter, gtol):
    """Iterate until the gradient norm is below `gtol`, the loss is zero, or the steps have
    stalled (two in a row shorter than `gtol (1 + |theta|)`: the loss is at the noise floor
    of the impact solves, which weighted residuals can put far above `gtol`)."""
    linesearch = optimizer is None
    opt = optax.lbfgs() if linesearch else optax.with_extra_args_support(optimizer)
    value_and_grad = (
        optax.value_and_grad_from_state(loss) if linesearch else jax.value_and_grad(loss)
    )
    history0 = jnp.zeros(max_iter + 1)

    def step(carry):
        theta, state, k, history, _, stalled = carry
        if linesearch:
            value, grad = value_and_grad(theta, data, state=state)
        else:
            value, grad = value_and_grad(theta, data)
        updates, state = opt.update(
            grad, state, theta, value=value, grad=grad, value_fn=lambda t: loss(t, data)
        )
        new_theta = optax.apply_updates(theta, updates)
        grad_norm = jnp.linalg.norm(grad)
        small = jnp.linalg.norm(new_theta - theta) <= gtol * (1.0 + jnp.linalg.norm(theta))
        stalled = jnp.where(small, stalled + 1, 0)
        return new_theta, state, k + 1, history.at[k].set(value), grad_norm, stalled

    def keep_going(carry):
        _, _, k, history, grad_norm, stalled = carry
        value = history[jnp.maximum(k - 1, 0)]
        return (k == 0) | ((k < max_iter) & (grad_norm > gtol) & (value > 1e-30) & (stalled < 2))

    zero = jnp.asarray(0)
    carry = (theta0, opt.init(theta0), zero, history0, jnp.asarray(jnp.inf), zero)
    theta, _, k, history, grad_norm, stalled = jax.lax.while_loop(keep_going, step, carry)
    value = history[jnp.maximum(k - 1, 0)]
    stopped = (grad_norm <= gtol) | (value <= 1e-30) | (stalled >= 2)
    return theta, k, history, stopped


def _run_lm(residuals, theta0, data, max_iter, tol):
    solution = optx.least_squares(
        residuals,
        optx.LevenbergMarquardt(rtol=tol, atol=tol),
        theta0,
        args=data,
        max_steps=max_iter,
        throw=False,
    )
    stopped = solution.result == optx.RESULTS.successful
    return solution.value, solution.stats["num_steps"], stopped


@quietly_compiled
def calibrate(
    law: AbstractLaw,
    *,
    m,
    v0,
    e=None,
    T=None,
    sigma_e=None,
    sigma_T=None,
    free=None,
    separation: str = "force",
    g=0.0,
    optimizer="auto",
    init: str = "auto",
    max_iter: int = 100,
    tol: float = 1e-12,
    target_tol: float | None = None,
    rtol: float = 1e-10,
    method: str = "auto",
    options: SolveOptions | None = None,
) -> Fit:
    """Fit `law`'s parameters to a measured restitution `e` and/or contact duration `T` (s).

    `v0` (m/s), `e` and `T` may be arrays, one row per impact speed; a row without `T` is
    `None` in a list (or NaN in an array). `m` is the (effective) mass in kg. `free` names
    the parameters to fit (default: the stiffness `c`, if some `T` is given, and the
    damping); the others keep the values in `law`. Parameters are fitted in a transformed
    space that keeps them physical (logarithms; a logit for `e_nominal`).

    - `optimizer`: `"auto"` (the default) is `"lm"` for an eager fit (nothing traced),
      else `"lbfgs"`; `"lbfgs"`: optax L-BFGS with a zoom line search inside the compiled
      fit; `"lm"`: Levenberg-Marquardt, for an eager fit driven from Python around one
      compiled program (the residuals, the peaks and the forward-mode Jacobian), which
      compiles the solve once where the in-graph optimisers compile it three times, else
      optimistix's inside the compiled fit; or any optax `GradientTransformation`.
      `Fit.optimizer` names the one that ran.
    - `init`: `"auto"` starts from the law's nondimensional restitution table (one damping
      group sets `e`, then `T` sets the stiffness) so most fits need a few iterations;
      `"given"` starts from the values in `law`.
    - `target_tol`: the largest residual a fit that `reproduces` the data may leave
      (default 1e-6 without sigmas, the data to numerical precision; 3 with them, i.e.
      three standard deviations). `converged` is the optimiser's own verdict, whatever
      the residuals; the goodness of fit is in `reduced_chi2` (with sigmas), `rms_e` and
      `rms_T`, and standard errors come from the sigmas or, without them, from the
      residuals' scatter (`Fit`).
    - `rtol`: tolerance of each impact solve.
    - `method`: `"auto"` reads every impact off the universal curves where they serve (a
      one-group law, `g = 0`; see `impact`), with the start read off them too (at one
      speed with `e` and `T`, that start is the answer), else takes the law's exact
      solution where it has one (Kelvin-Voigt, Bingham 7 and 9 with any `g`, Maxwell at
      `g = 0`); `"similarity"` insists, `"integrate"` solves the ODE for every impact.
      `choose_path(..., fit=True)` decides it, once, before the fit is compiled.
    - `options`: a `SolveOptions` for every impact solve, whole: `rtol` (a keyword `rtol`
      that sets it otherwise is refused), `atol` (default `rtol`), `max_steps`, `tau_max`,
      `rest_tol` (default 1e-9), `solver` (choosing one integrates); the fit differentiates
      in forward mode and asks for the peaks itself, so `adjoint`, `peaks` and `throw`
      stay None.
    A batch of fits (one body per element: its own mass, speeds and targets) is `jax.vmap`
    over a lambda, `jax.jit(jax.vmap(lambda m, e, T: calibrate(start, m=m, v0=v0, e=e, T=T)))`,
    which returns one `Fit` whose fields carry a leading batch axis; a batch runs until its
    slowest member has converged (benchmarks/calibrate.md times 10 000 such fits). Concrete
    inputs are refused (ValueError: m or v0 <= 0, e outside (0, 1], T <= 0, NaN, rows of
    different lengths); under `jit` or `vmap` a member whose inputs would be refused is
    not fitted: its `params`, `e`, `T`, `loss` are NaN and `converged` is False.

    **Example**:
    `calibrate(law("hertz_rate", c=1e6, b1=100.0), m=1.0, v0=2.5, e=0.85, T=7.8e-3)`.
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError("calibrate needs a law from jaximpact.law(...) or custom_law(...)")
    if optimizer not in OPTIMIZERS and not isinstance(optimizer, optax.GradientTransformation):
        raise ValueError(
            f"optimizer must be one of {OPTIMIZERS} or an optax GradientTransformation"
        )
    if init not in ("auto", "given"):
        raise ValueError(f"init must be 'auto' or 'given', got {init!r}")
    v0 = _as_rows("v0", v0, None)
    rows = v0.shape[0]
    if rows == 0:
        raise ValueError("v0 is empty: give at least one impact speed (m/s) and its e")
    if np.ndim(m) != 0:
        raise ValueError(f"m must be one number (kg) for every row, got shape {np.shape(m)}")
    if isinstance(free, str):
        raise TypeError(f"free takes a tuple of parameter names, e.g. free=({free!r},)")
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    e = _as_rows("e", e, rows)
    T = _as_rows("T", T, rows, allow_missing=True)
    sigma_e = _as_rows("sigma_e", sigma_e, rows)
    sigma_T = _as_rows("sigma_T", sigma_T, rows)
    sticks = law.spec is not None and law.spec.captures
    # eager: a one-line ValueError; traced: a bad member is NaN and invalid (`MemberChecks`)
    checks = MemberChecks()
    m, v0, e, T, sigma_e, sigma_T = check_targets(
        m, v0, e, T, sigma_e, sigma_T, sticks=sticks, checks=checks
    )
    m = jnp.asarray(m, dtype=float) if is_traced(m) else np.float64(m)
    has_sigma = sigma_e is not None or sigma_T is not None
    if free is None:
        free = default_free(law, stiffness=T is not None)
        held = [k for k in law.parameters if k not in free]
        if T is not None and stiffness_parameter(law) is None and held:
            warnings.warn(
                f"T is given but the law has no stiffness named c (or k beside a damping c), "
                f"so only {', '.join(free)} "
                f"is fitted and {', '.join(held)} stays at its start value; name the "
                f"stiffness among the free parameters to fit it, e.g. free={(*held[:1], *free)}",
                stacklevel=3,
            )
    free = tuple(free)
    unknown = [k for k in free if k not in law.parameters]
    if unknown:
        raise ValueError(
            f"cannot fit {', '.join(unknown)}: the law's parameters are {', '.join(law.parameters)}"
        )
    if not free:
        raise ValueError("free names no parameter to fit")
    g_is_zero = is_no_gravity(g)
    undetermined, undetermined_why = _undetermined(law, free, e=e, T=T, g_is_zero=g_is_zero)
    solve = solve_options(calibrate, options, rtol=rtol, refused=FIT_DECIDES)
    # the path, once: its curves are loaded (or built) now, before the fit is compiled
    path = choose_path(
        law,
        separation=separation,
        method=method,
        g=g,
        solver=solve.solver,
        rtol=solve.rtol,
        fit=True,
    )
    # an eager fit runs its optimiser in Python around one compiled program; a traced one
    # (jit, vmap) runs it inside the compiled fit
    eager = not any(is_traced(x) for x in jax.tree.leaves((law, m, v0, e, T, sigma_e, sigma_T, g)))
    on_host = eager and optimizer in ("auto", "lm")
    if optimizer == "auto":
        optimizer = "lm" if on_host else "lbfgs"
    start_on_curves = init == "auto" and path.name == "similarity"
    if init == "auto" and not start_on_curves:
        law = _initial_law(law, free, m=m, v0=v0, e=e, T=T, separation=separation)

    ones = np.ones(rows)
    s_e = ones if sigma_e is None else sigma_e
    if sigma_T is not None:
        s_T = sigma_T
    else:
        xp = jnp if is_traced(T) else np
        s_T = ones if T is None else xp.where(xp.isfinite(T), T, 1.0)
    data = (v0, ones if e is None else e, ones if T is None else T, s_e, s_T)
    target_tol = (3.0 if has_sigma else 1e-6) if target_tol is None else target_tol
    options = _Options(
        free=free,
        optimizer=optimizer,
        max_iter=max_iter,
        tol=tol,
        has_e=e is not None,
        has_T=T is not None,
        has_sigma=has_sigma,
        impact=_impact_options(path, solve, separation=separation, g=g),
        start_on_curves=start_on_curves,
    )
    # g = 0 as a Python number is static to filter_jit (a numpy scalar would be traced):
    # the formulas without gravity are compiled alone
    fit = (_fit_on_host if on_host else _fit)(
        law,
        data,
        m,
        0.0 if g_is_zero else jnp.asarray(g, dtype=float),
        np.float64(target_tol),
        options,
    )
    fit = checks.refuse(fit, keep=("target_tol", "n_data"), converged=False, reproduces=False)
    fit = dataclasses.replace(fit, sigma_e=sigma_e, sigma_T=sigma_T)  # for `posterior`
    e_only = T is None and g_is_zero and shape_of(law) is not None
    return _reported(fit, undetermined, undetermined_why, e_only)


def _reported(fit, undetermined, why, e_only=False):
    """`fit` with what the data leave undetermined (a warning too) and, where `e` alone
    was measured for a one-group law (`e_only`), the group it determined (`notes`), after
    refusing one that left float64's range; under a transformation only the record."""
    concrete = not is_traced(fit.loss)
    if concrete:
        _check_finite(fit)
        if fit.stderr is not None and not fit.weighted:
            if all(np.all(np.isnan(np.asarray(v))) for v in fit.stderr.values()):
                fit = dataclasses.replace(fit, stderr=None)  # no degree of freedom left
        if e_only and np.ndim(fit.loss) == 0:
            fit = dataclasses.replace(fit, notes=(*fit.notes, *_group_notes(fit, undetermined)))
    if not undetermined:
        return fit
    if concrete:
        warnings.warn(
            f"{' and '.join(undetermined)} not determined by these data ({why}): "
            "their values are not estimates; give T (or more data), or hold one of them "
            "(free=...)",
            stacklevel=3,
        )
    return dataclasses.replace(fit, undetermined=undetermined)


def _group_notes(fit, undetermined) -> tuple[str, ...]:
    """What `e` alone determined for a one-group law (no `T`, no gravity): `e` depends on
    the damping group `beta` alone, so the fit fixes `beta` at each speed; the stiffness
    held fixed (or left undetermined) sets how that group splits into parameters."""
    law = fit.law
    damping = damping_parameter(law)
    shape = shape_of(law)
    if shape is None or damping not in fit.free:
        return ()
    n, p = shape
    v0 = np.asarray(fit.v0, dtype=float)
    m = float(fit.m)

    def betas(item):
        return np.asarray([float(item.dynamics(m=m, v0=float(v), g=0.0).beta) for v in v0])

    beta = betas(law)
    c = float(law.parameters["c"])
    with_c = betas(law.replace(c=2.0 * c))
    c_enters = not np.allclose(with_c, beta, rtol=1e-9, atol=0.0)
    units = law_units(law)
    group = (
        f"e depends on the damping group beta alone (beta = b x*^{p + 1:g}/(m v0), "
        f"x* = (m v0^2/c)^(1/{n + 1:g}), b the coefficient of x^{p:g} v): e determines "
        f"beta = {format_value(beta)} at v0 = {format_value(v0, 'm/s')}"
    )
    if "c" in undetermined:
        return (f"{group}; c and {damping} separately are not determined: give T",)
    value = format_value(law.parameters[damping], units.get(damping, ""))
    held = f"c held at its start value {format_value(c, units.get('c', ''))}"
    if c_enters:
        return (
            f"{group}; {held}: {damping} = {value} is the value that gives this beta with "
            f"that c (another c gives another {damping} and the same e; give T to fit c)",
        )
    return (
        f"{group}, which does not involve c: {damping} = {value} is determined; {held} "
        "(c sets T and x_max, not e: give T to fit it)",
    )


def _check_finite(fit):
    """A fit whose parameters left float64's range (targets no law of this kind meets, e.g.
    T = 1e-300 s) is refused with the values it reached, not returned."""
    bad = {k: float(v) for k, v in fit.params.items() if not np.all(np.isfinite(v))}
    if bad:
        shown = ", ".join(f"{k} = {v:g}" for k, v in bad.items())
        raise ValueError(
            f"the fit left the range of float64 ({shown}): no {type(fit.law).__name__} of "
            "this kind meets these targets; check their values and units (e in (0, 1], T in s)"
        )


def _undetermined(law, free, *, e, T, g_is_zero) -> tuple[tuple[str, ...], str]:
    """The free parameters the targets cannot fix, and why: fewer targets than free
    parameters; or, for a one-group law without gravity and no `T`, the stiffness and the
    damping together (`e` depends on the group `beta` alone, whatever the speeds)."""

    def count(values):
        if values is None:
            return 0
        if is_traced(values):
            return values.shape[0]
        return int(np.sum(np.isfinite(np.asarray(values))))

    n_data = count(e) + count(T)
    if n_data < len(free):
        return tuple(free), f"{n_data} target value(s) for {len(free)} free parameters"
    damping = damping_parameter(law)
    if T is None and g_is_zero and shape_of(law) is not None and {"c", damping} <= set(free):
        return ("c", damping), f"e alone fixes only the group beta that c and {damping} make"
    return (), ""


class _Options(eqx.Module):
    """What is static about a fit (its `Fit.setup`): the free parameters, the optimiser
    and its budget, which targets were given, and `impact`, the `ImpactOptions` of its
    solves (separation, tolerance, the path: `curves`, `closed_form`)."""

    free: tuple = eqx.field(static=True)
    optimizer: object = eqx.field(static=True)
    max_iter: int = eqx.field(static=True)
    tol: float = eqx.field(static=True)
    has_e: bool = eqx.field(static=True)
    has_T: bool = eqx.field(static=True)
    has_sigma: bool = eqx.field(static=True)
    impact: ImpactOptions
    start_on_curves: bool = eqx.field(static=True, default=False)

    @property
    def separation(self) -> str:
        return self.impact.separation

    @property
    def rtol(self) -> float:
        return self.impact.rtol

    @property
    def curves(self):
        """The universal curves' `CurveKey`, or a two-group table's key, or None."""
        return self.impact.similarity

    @property
    def closed_form(self) -> bool:
        return self.impact.closed_form


def _solved_by_start(law, options, rows) -> bool:
    """One speed, e and T, stiffness and damping free: the start read off the curves is the
    solution itself (two equations, two unknowns), so no optimiser runs."""
    return (
        options.start_on_curves
        and rows == 1
        and options.has_e
        and options.has_T
        and set(options.free) == {"c", damping_parameter(law)}
        and damping_parameter(law) != "e_nominal"  # not read off the curves (a formula)
    )


@eqx.filter_jit
def _fit(law, data, m, g, target_tol, options):
    """The compiled part of `calibrate`: optimise, then evaluate the fit."""
    free, optimizer = options.free, options.optimizer
    v0, e, T = data[0], data[1], data[2]
    rows = v0.shape[0]
    if options.start_on_curves and options.has_e:
        law = _start_on_curves(
            law, free, m=m, v0=v0, e=e, T=T, has_T=options.has_T, key=options.curves
        )
    targets = dict(m=m, g=g, has_e=options.has_e, has_T=options.has_T)
    raw = _residuals(law, free, options.impact, **targets)
    # one traced copy of the residuals and of their Jacobian, shared by every call site
    raw = jax.jit(raw)
    jacobian_fn = jax.jit(lambda theta, data: value_and_jacobian(raw, theta, data))
    residuals = with_forward_jacobian(lambda theta, data: raw(theta, data)[0], jacobian_fn)

    def loss(theta, data):
        r = residuals(theta, data)
        return 0.5 * jnp.sum(r**2)

    theta0 = jnp.stack([to_unbounded(k, law.parameters[k]) for k in free])
    exact = _solved_by_start(law, options, rows)
    if exact:
        theta, iterations, stopped, history = theta0, jnp.asarray(0), jnp.asarray(True), None
    elif optimizer == "lm":
        theta, iterations, stopped = _run_lm(residuals, theta0, data, options.max_iter, options.tol)
        history = None
    else:
        theta, iterations, history, stopped = _run_lbfgs(
            loss,
            theta0,
            data,
            None if optimizer == "lbfgs" else optimizer,
            options.max_iter,
            gtol=options.tol,
        )
    # the final point once more, with the peaks (x_max, F_max: the sanity echo); on the
    # curves they cost nothing, an integrated law adds their events to this one solve
    final = _residuals(law, free, dataclasses.replace(options.impact, peaks=True), **targets)
    r, predictions = final(theta, data)
    (_, _), jacobian = jacobian_fn(theta, data)
    final_loss = 0.5 * jnp.sum(r**2)
    if history is None:
        history = jnp.stack([loss(theta0, data), final_loss])[-1 if exact else 0 :]
    else:  # L-BFGS's fixed-length record: the steps not taken hold the final loss
        history = jnp.where(jnp.arange(history.shape[0]) < iterations, history, final_loss)
    name = optimizer if isinstance(optimizer, str) else type(optimizer).__name__
    solved = (theta, r, predictions, jacobian, history, iterations, stopped)
    return _recorded(law, solved, data, m, g, target_tol, options, exact=exact, optimizer=name)


def _recorded(law, solved, data, m, g, target_tol, options, *, exact, optimizer):
    """The `Fit` of a solved fit: `solved` is `(theta, r, (e, T, status, x_max, F_max),
    jacobian, history, iterations, stopped)` at the optimiser's last point; the goodness of
    fit and the standard errors (from `J^T J`) follow from them."""
    theta, r, (e_fit, T_fit, status, x_max, F_max), jacobian, history, iterations, stopped = solved
    free = options.free
    v0, e, T = data[0], data[1], data[2]
    rows = v0.shape[0]
    final_loss = 0.5 * jnp.sum(r**2)
    fitted = law_with(law, free, theta)
    # every impact separated; with a law that holds the body (adhesion), a row measured as
    # stuck (e = 0) is matched by a captured impact
    stuck_row = (law.spec is not None and law.spec.captures) & (e == 0) & options.has_e
    separated = jnp.all((status == Status.separated) | (stuck_row & (status == Status.captured)))
    reproduces = jnp.all(jnp.abs(r) <= target_tol) & separated
    if exact:  # no optimiser ran: converged where the curves' solution meets the targets
        known = jnp.isfinite(T)
        T_known = jnp.where(known, T, 1.0)
        T_off = jnp.where(known, jnp.abs(T_fit - T_known) / T_known, 0.0)
        stopped = jnp.all(jnp.abs(e_fit - e) <= 1e-6) & jnp.all(T_off <= 1e-6)
    n_data = (rows if options.has_e else 0) + (jnp.sum(jnp.isfinite(T)) if options.has_T else 0)
    dof = n_data - len(free)
    # without sigmas the residuals' own scatter stands for every residual's variance
    variance = 1.0 if options.has_sigma else jnp.sum(r**2) / jnp.where(dof > 0, dof, 1)
    covariance = variance * jnp.linalg.pinv(jacobian.T @ jacobian)
    params = jnp.stack([fitted.parameters[k] for k in free])
    scale = jnp.where(jnp.asarray([k == "e_nominal" for k in free]), params * (1 - params), params)
    se = scale * jnp.sqrt(jnp.abs(jnp.diag(covariance)))
    if not options.has_sigma:
        se = jnp.where(dof > 0, se, jnp.nan)
    stderr = {k: se[i] for i, k in enumerate(free)}
    return Fit(
        law=fitted,
        params=fitted.parameters,
        v0=v0,
        e=e_fit,
        T=T_fit,
        e_target=e if options.has_e else jnp.full(rows, jnp.nan),
        T_target=T if options.has_T else jnp.full(rows, jnp.nan),
        residuals=r,
        loss=final_loss,
        converged=(stopped & separated) | (final_loss <= 1e-30),
        iterations=jnp.asarray(iterations),
        history=history,
        stderr=stderr,
        free=free,
        m=jnp.asarray(m, dtype=float),
        x_max=x_max,
        F_max=F_max,
        reproduces=reproduces,
        target_tol=jnp.asarray(target_tol, dtype=float),
        n_data=jnp.asarray(n_data),
        weighted=options.has_sigma,
        optimizer=optimizer,
        g=g,
        setup=options,
    )


# ----------------------------------------------------------- an eager fit: one program


def _evaluated(law, theta, data, m, g, options):
    """`(r, (e, T, status, x_max, F_max), J)` at `theta`: the one compiled program of a fit
    driven from Python (the residuals with the peaks and their forward-mode Jacobian)."""
    with_peaks = dataclasses.replace(options.impact, peaks=True)
    predict = _predictions(law, options.free, with_peaks, m=m, g=g)
    ((e, T, x_max, F_max), status), (de, dT, _, _) = rows_value_and_jacobian(
        predict, theta, data[0]
    )
    weighted = functools.partial(_weighted, data=data, has_e=options.has_e, has_T=options.has_T)
    # the residuals are linear in (e, T): their Jacobian is theirs applied to (de, dT)
    jacobian = jax.vmap(
        lambda de_k, dT_k: jax.jvp(weighted, (e, T), (de_k, dT_k))[1], in_axes=-1, out_axes=-1
    )(de, dT)
    return weighted(e, T), (e, T, status, x_max, F_max), jacobian


# an integrated law's program at XLA's defaults; the others compiled quickly, and briefly
# where they integrate nothing (`_compiling`)
_evaluated_compiled = {
    "integrated": stored_jit(_evaluated),
    "quick": quick_jit(_evaluated),
    "brief": quick_jit(_evaluated, brief=True),
}


def _program(impact: ImpactOptions) -> str:
    """Which of `_evaluated_compiled` serves a fit's solves: `"integrated"` where they are
    all integrated, `"quick"` for a two-group table that integrates the impacts outside it
    (compiled quickly: `bingham_modified` 12.5 -> 9.8 CPU s, each fit 2 ms slower),
    `"brief"` for a closed form, the curves or a table alone."""
    if not impact.closed_form and impact.similarity is None:
        return "integrated"
    if isinstance(impact.similarity, WithGravity) and impact.integrate_outside:
        return "quick"
    return "brief"


_recorded_compiled = quick_jit(_recorded, brief=True)
# the largest step of a parameter (a logarithm, or a logit for `e_nominal`) in one iteration,
# a factor e^2 = 7.4: a longer one from a far start can saturate the logit, where the loss is
# flat and the fit stops (Lankarani-Nikravesh from e_nominal = 0.08 went to 1)
_MAX_STEP = 2.0
_start_compiled = quick_jit(_start_on_curves, brief=True)


def _fit_on_host(law, data, m, g, target_tol, options):
    """An eager fit: `levenberg_marquardt`'s numpy loop around `_evaluated`, traced and
    compiled once (the in-graph optimisers' program holds the solve three times: the
    loss's, the Jacobian's and the final one with the peaks), then `_fit`'s record."""
    v0, e, T = data[0], data[1], data[2]
    if options.start_on_curves and options.has_e:
        law = _start_compiled(
            law, options.free, m=m, v0=v0, e=e, T=T, has_T=options.has_T, key=options.curves
        )
    theta0 = np.stack([np.asarray(to_unbounded(k, law.parameters[k])) for k in options.free])

    # a two-group table's program first without the integration of the impacts outside
    # it: that is compiled (about 8 s of a 10 s first fit) only at a point where an
    # impact leaves the table
    table_first = isinstance(options.impact.similarity, WithGravity)
    if table_first:
        table_only = dataclasses.replace(
            options, impact=dataclasses.replace(options.impact, integrate_outside=False)
        )

    def evaluate(theta):
        theta = jnp.asarray(theta)
        if table_first:
            r, predictions, jacobian = _evaluated_compiled["brief"](
                law, theta, data, m, g, table_only
            )
            if not np.any(np.asarray(predictions[2]) == Status.failed):
                return np.asarray(r), np.asarray(jacobian), predictions
        evaluated = _evaluated_compiled[_program(options.impact)]
        r, predictions, jacobian = evaluated(law, theta, data, m, g, options)
        return np.asarray(r), np.asarray(jacobian), predictions

    exact = _solved_by_start(law, options, v0.shape[0])
    if exact:
        r, jacobian, predictions = evaluate(theta0)
        history = np.asarray([0.5 * float(r @ r)])
        result = LeastSquares(theta0, r, jacobian, predictions, history, True, 0)
    else:
        result = levenberg_marquardt(
            evaluate, theta0, max_iter=options.max_iter, tol=options.tol, max_step=_MAX_STEP
        )
    # the history padded with the final loss to L-BFGS's fixed length, and every number an
    # array: one compiled record for every fit of these shapes
    history = np.full(options.max_iter + 1, result.history[-1])
    history[: len(result.history)] = result.history
    solved = (
        jnp.asarray(result.theta),
        jnp.asarray(result.residuals),
        result.extra,
        jnp.asarray(result.jacobian),
        jnp.asarray(history),
        jnp.asarray(result.iterations),
        jnp.asarray(result.converged),
    )
    return _recorded_compiled(
        law, solved, data, m, g, target_tol, options, exact=exact, optimizer="lm"
    )
