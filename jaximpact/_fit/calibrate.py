"""Fitting a law's parameters to measured restitution and contact duration."""

import dataclasses
import warnings

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
import optimistix as optx
from jaxtyping import Array

from .._checks import check_scale
from .._curves.shapes import curve_key
from .._curves.similarity import beta_for_restitution, curve_values
from .._curves.store import curves_for
from .._format import concrete_units, format_fields, format_value, is_traced, jsonable
from .._laws import AbstractLaw, damping_parameter, shape_of
from .._solve.impact import CURVES_RTOL, ImpactOptions, similarity_reason, solve_impact
from .._status import Status
from .forward_jacobian import value_and_jacobian, with_forward_jacobian
from .parameters import default_free, law_with, to_unbounded
from .restitution_tables import restitution_table

OPTIMIZERS = ("lbfgs", "lm")


class Fit(eqx.Module):
    """A calibrated law and how well it reproduces the measurements.

    - `law`, `params`: the fitted law and its parameters (SI units).
    - `e`, `T`: predicted restitution and contact duration (s) at every row's `v0`.
    - `residuals`: weighted residuals, `(e_fit - e)/sigma_e` then `(T_fit - T)/sigma_T`
      (without sigmas: `e_fit - e` and `(T_fit - T)/T`); 0 for a row without `T`.
    - `loss`: half the sum of squared residuals; `history`: the loss at each iteration.
    - `converged`: the optimiser stopped at a minimum and every residual is below
      `target_tol` (a target the law cannot reach gives `False`, with the best fit).
    - `iterations`; `stderr`: standard errors of the free parameters (from the Jacobian,
      only when sigmas are given), `None` otherwise.
    - `undetermined`: free parameters these data cannot fix (fewer data than free
      parameters, or `e` alone for a one-group law, which fixes only the group `beta`
      that stiffness and damping make together); their values are not estimates. A
    warning says so when the fit is not traced.
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

    def summary(self) -> str:
        """The fit as text: each parameter with its unit (and standard error, or `fixed`,
        or `undetermined`), how the optimiser ended, then e and T predicted beside their
        targets at each speed; inside `jit` the shapes (`traced f64[]`)."""
        units = law_units(self.law)
        order = [k for k in getattr(self.law, "parameters", {}) if k in self.params]
        order += [k for k in self.params if k not in order]  # the law's order, not jit's
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
        rows += [
            ("converged", format_value(self.converged, None)),
            ("iterations", format_value(self.iterations, None)),
            ("loss", format_value(self.loss)),
            ("v0", format_value(self.v0, "m/s")),
            ("e", f"{format_value(self.e)} ({_target_text(self.e_target, '')})"),
            ("T", f"{format_value(self.T, 's')} ({_target_text(self.T_target, 's')})"),
        ]
        name = getattr(self.law, "name", type(self.law).__name__)
        return format_fields(f"Fit of {name} ({self.optimizer}; SI units)", rows)

    def to_dict(self) -> dict:
        """The fit as plain numbers and lists (SI units), NaN as None: `law` (name and
        parameters), `params`, `stderr`, `free`, `undetermined`, `converged`, `iterations`,
        `loss`, `history`, and per speed `v0`, `e`, `T`, `e_target`, `T_target`,
        `residuals`. Concrete fits only (not inside `jit`)."""
        names = ("params", "stderr", "converged", "iterations", "loss", "history", "v0", "e",
                 "T", "e_target", "T_target", "residuals")  # fmt: skip
        out = {k: jsonable(getattr(self, k)) for k in names}
        law = {"name": getattr(self.law, "name", type(self.law).__name__)}
        law["parameters"] = out["params"]
        return {"law": law, **out, "free": list(self.free), "optimizer": self.optimizer,
                "undetermined": list(self.undetermined)}  # fmt: skip

    def __repr__(self) -> str:
        return self.summary()


def _target_text(target, unit: str) -> str:
    """`target 7.8 ms`, or `not measured` where no row has one (NaN)."""
    if not is_traced(target) and not np.any(np.isfinite(np.asarray(target))):
        return "not measured"
    return f"target {format_value(target, unit)}"


def law_units(law) -> dict[str, str]:
    """The units of `law`'s parameters (`{"c": "N/m^1.5", ...}`; "" for a pure number);
    a user's own law has none to give."""
    spec = getattr(law, "spec", None)
    if spec is None:
        return {}
    try:
        units = concrete_units(spec, law.parameters)
    except Exception:  # an exponent that is traced: the family's own spelling (`N/m^n`)
        units = {k: spec.units.get(k, "") for k in spec.parameters}
    return {k: "" if u == "-" else u for k, u in units.items()}


def _as_rows(name, value, rows, allow_missing=False):
    """`value` as one entry per row: numpy for concrete inputs (no eager JAX dispatch, which
    would cost more than a fit on the curves), `jax.numpy` for traced ones."""
    if value is None:
        return None
    if isinstance(value, (list, tuple)):
        if allow_missing:
            value = [np.nan if item is None else item for item in value]
        value = np.asarray(value, dtype=float)
    xp = jnp if isinstance(value, jax.core.Tracer) else np
    value = xp.atleast_1d(xp.asarray(value, dtype=float))
    if value.ndim != 1:
        raise ValueError(f"{name} must be a number or a 1-D array, got shape {value.shape}")
    if rows is not None and value.shape[0] not in (1, rows):
        raise ValueError(
            f"{name} has {value.shape[0]} values but v0 has {rows}: give one per impact speed"
        )
    return xp.broadcast_to(value, (rows,)) if rows is not None else value


def check_targets(m, v0, e, T, sigma_e, sigma_T):
    """One-line ValueErrors for impossible targets (only for concrete inputs)."""
    concrete = not any(isinstance(a, jax.core.Tracer) for a in (m, v0, e, T, sigma_e, sigma_T))
    if not concrete:
        return
    if not np.all(np.asarray(m) > 0) or not np.all(np.isfinite(np.asarray(m))):
        raise ValueError(f"mass m must be a finite number > 0 kg, got {np.asarray(m)}")
    if np.any(~np.isfinite(np.asarray(v0))) or np.any(np.asarray(v0) <= 0):
        raise ValueError("every impact speed v0 must be a finite number > 0 m/s")
    if e is not None:
        ea = np.asarray(e)
        if np.any(np.isnan(ea)):
            raise ValueError("e contains NaN; every row needs a measured restitution")
        if np.any((ea <= 0) | (ea > 1)):
            raise ValueError(f"restitution e must lie in (0, 1], got {ea[(ea <= 0) | (ea > 1)]}")
    if T is not None:
        Ta = np.asarray(T)
        if np.all(np.isnan(Ta)):
            raise ValueError("T has no value; leave T=None to fit e alone")
        if np.any(Ta[~np.isnan(Ta)] <= 0) or np.any(np.isinf(Ta)):
            raise ValueError("contact durations T must be finite and > 0 s (None: no T)")
    for name, sigma in (("sigma_e", sigma_e), ("sigma_T", sigma_T)):
        if sigma is not None and (
            np.any(~np.isfinite(np.asarray(sigma))) or np.any(np.asarray(sigma) <= 0)
        ):
            raise ValueError(f"{name} must be finite and > 0")
    if e is None and T is None:
        raise ValueError("give e, T or both to calibrate against")
    # sizes float64 carries through a fit: 1e-300 kg refused as 1e300 kg is
    check_scale("mass m", m, "kg")
    check_scale("impact speed v0", v0, "m/s")
    check_scale("contact energy m v0^2", np.asarray(m, float) * np.asarray(v0, float) ** 2, "J")
    for name, value, unit in (("T", T, "s"), ("sigma_e", sigma_e, ""), ("sigma_T", sigma_T, "s")):
        if value is not None:
            check_scale(name, value, unit)
    if T is not None:
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


# the reach v0 T (m) above which a target is flagged as implausible for a compliant contact
MAX_REACH = 1.0


# ------------------------------------------------------------------- initial values


def _initial_law(law, free, *, m, v0, e, T, separation):
    """Start from one dimensionless damping group: `e` sets it (through a table of the
    law's nondimensional impact), `T` then sets the time scale and so the stiffness."""
    spec = getattr(law, "spec", None)
    if spec is None or not spec.restitution_table:
        return law
    damping = spec.damping
    if damping not in free or e is None:
        return law
    if isinstance(law.params.get("n", 0.0), jax.core.Tracer):
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
    if spec.coefficients is None:  # Maxwell: group b / sqrt(m c), tau = T / sqrt(m / c)
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
    """The start read off the curves (inside the compiled fit): `beta` from `e` at the
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


def _residual_function(law, free, *, m, separation, g, rtol, has_e, has_T, curves=None):
    """Weighted residuals and predictions; differentiated in forward mode only (through
    `with_forward_jacobian`), hence the explicit `ForwardMode` adjoint. With `curves` (a
    `CurveKey`) every impact is read off the universal curves: no ODE solve."""
    options = ImpactOptions(
        separation=separation,
        closed_form=False,
        solver=dfx.Tsit5(),
        rtol=rtol,
        atol=rtol,
        max_steps=4096,
        tau_max=1e4,
        rest_tol=1e-9,
        adjoint=dfx.ForwardMode(),
        peaks=False,
        similarity=curves,
    )

    def residuals(theta, data):
        v0, e, T, s_e, s_T = data
        fitted = law_with(law, free, theta)
        result = jax.vmap(lambda v: solve_impact(fitted, m, v, g, None, options))(v0)
        parts = []
        predictions = (result.e, result.T, result.status)
        if has_e:
            parts.append((result.e - e) / s_e)
        if has_T:
            known = jnp.isfinite(T)
            T_safe = jnp.where(known, T, 1.0)
            parts.append(jnp.where(known, (result.T - T_safe) / s_T, 0.0))
        return jnp.concatenate(parts), predictions

    return residuals


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
    optimizer="lbfgs",
    init: str = "auto",
    max_iter: int = 100,
    tol: float = 1e-12,
    target_tol: float | None = None,
    rtol: float = 1e-10,
    method: str = "auto",
) -> Fit:
    """Fit `law`'s parameters to a measured restitution `e` and/or contact duration `T` (s).

    `v0` (m/s), `e` and `T` may be arrays, one row per impact speed; a row without `T` is
    `None` in a list (or NaN in an array). `m` is the (effective) mass in kg. `free` names
    the parameters to fit (default: the stiffness `c`, if some `T` is given, and the
    damping); the others keep the values in `law`. Parameters are fitted in a transformed
    space that keeps them physical (logarithms; a logit for `e_nominal`).

    - `optimizer`: `"lbfgs"` (the default: optax L-BFGS with a zoom line search), `"lm"`
      (optimistix Levenberg-Marquardt), or any optax `GradientTransformation`.
    - `init`: `"auto"` starts from the law's nondimensional restitution table (one damping
      group sets `e`, then `T` sets the stiffness) so most fits need a few iterations;
      `"given"` starts from the values in `law`.
    - `target_tol`: the largest residual a converged fit may leave (default 1e-6 without
      sigmas, 3 with them, i.e. three standard deviations).
    - `rtol`: tolerance of each impact solve.
    - `method`: `"auto"` reads every impact off the universal curves where they serve (a
      one-group law, `g = 0`; see `impact`), with the start read off them too (at one
      speed with `e` and `T`, that start is the answer); `"similarity"` insists,
      `"integrate"` solves the ODE for every impact.
    A batch of fits (one body per element: its own mass, speeds and targets) is `jax.vmap`
    over a lambda, `jax.jit(jax.vmap(lambda m, e, T: calibrate(start, m=m, v0=v0, e=e, T=T)))`,
    which returns one `Fit` whose fields carry a leading batch axis; a batch runs until its
    slowest member has converged (benchmarks/calibrate.md times 10 000 such fits). Targets
    are refused (ValueError: e outside (0, 1], T <= 0, NaN, rows of different lengths) only
    when they are concrete, so check a batch's targets before mapping over them.

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
    check_targets(m, v0, e, T, sigma_e, sigma_T)
    m = jnp.asarray(m, dtype=float) if isinstance(m, jax.core.Tracer) else np.float64(m)
    has_sigma = sigma_e is not None or sigma_T is not None
    free = default_free(law, stiffness=T is not None) if free is None else tuple(free)
    unknown = [k for k in free if k not in law.parameters]
    if unknown:
        raise ValueError(
            f"cannot fit {', '.join(unknown)}: the law's parameters are {', '.join(law.parameters)}"
        )
    if not free:
        raise ValueError("free names no parameter to fit")
    g_is_zero = isinstance(g, (int, float)) and g == 0
    undetermined, undetermined_why = _undetermined(law, free, e=e, T=T, g_is_zero=g_is_zero)
    curves = None
    if method in ("auto", "similarity"):
        reason = similarity_reason(law, separation, g_is_zero=g_is_zero)
        if reason is None and (method == "similarity" or rtol >= CURVES_RTOL):
            curves = curve_key(*shape_of(law), separation)
        elif method == "similarity":
            raise ValueError(f"method='similarity' cannot serve this fit: {reason}")
    elif method != "integrate":
        raise ValueError(f"method must be 'auto', 'similarity' or 'integrate', got {method!r}")
    if init == "auto" and curves is None:
        law = _initial_law(law, free, m=m, v0=v0, e=e, T=T, separation=separation)

    ones = np.ones(rows)
    s_e = ones if sigma_e is None else sigma_e
    if sigma_T is not None:
        s_T = sigma_T
    else:
        xp = jnp if isinstance(T, jax.core.Tracer) else np
        s_T = ones if T is None else xp.where(xp.isfinite(T), T, 1.0)
    data = (v0, ones if e is None else e, ones if T is None else T, s_e, s_T)
    target_tol = (3.0 if has_sigma else 1e-6) if target_tol is None else target_tol
    options = _Options(
        free=free,
        separation=separation,
        optimizer=optimizer,
        max_iter=max_iter,
        tol=tol,
        rtol=rtol,
        has_e=e is not None,
        has_T=T is not None,
        has_sigma=has_sigma,
        curves=curves,
        start_on_curves=init == "auto" and curves is not None,
    )
    fit = _fit(law, data, m, np.float64(g) if g_is_zero else jnp.asarray(g, dtype=float),
               np.float64(target_tol), options)  # fmt: skip
    return _reported(fit, undetermined, undetermined_why)


def _reported(fit, undetermined, why):
    """`fit` with what the data leave undetermined (a warning too), after refusing one that
    left float64's range; under a transformation only the record."""
    concrete = not isinstance(fit.loss, jax.core.Tracer)
    if concrete:
        _check_finite(fit)
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
        if isinstance(values, jax.core.Tracer):
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
    free: tuple = eqx.field(static=True)
    separation: str = eqx.field(static=True)
    optimizer: object = eqx.field(static=True)
    max_iter: int = eqx.field(static=True)
    tol: float = eqx.field(static=True)
    rtol: float = eqx.field(static=True)
    has_e: bool = eqx.field(static=True)
    has_T: bool = eqx.field(static=True)
    has_sigma: bool = eqx.field(static=True)
    curves: object = eqx.field(static=True, default=None)
    start_on_curves: bool = eqx.field(static=True, default=False)


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
    raw = _residual_function(
        law,
        free,
        m=m,
        separation=options.separation,
        g=g,
        rtol=options.rtol,
        has_e=options.has_e,
        has_T=options.has_T,
        curves=options.curves,
    )
    # one traced copy of the residuals and of their Jacobian, shared by every call site
    raw = jax.jit(raw)
    jacobian_fn = jax.jit(lambda theta, data: value_and_jacobian(raw, theta, data))
    residuals = with_forward_jacobian(lambda theta, data: raw(theta, data)[0], jacobian_fn)

    def loss(theta, data):
        r = residuals(theta, data)
        return 0.5 * jnp.sum(r**2)

    theta0 = jnp.stack([to_unbounded(k, law.parameters[k]) for k in free])
    # one speed, e and T, stiffness and damping free: the start read off the curves is the
    # solution itself (two equations, two unknowns), so no optimiser runs
    exact = (
        options.start_on_curves
        and rows == 1
        and options.has_e
        and options.has_T
        and set(free) == {"c", damping_parameter(law)}
        and damping_parameter(law) != "e_nominal"  # not read off the curves (a formula)
    )
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
    if options.has_sigma:
        (r, (e_fit, T_fit, status)), jacobian = jacobian_fn(theta, data)
    else:
        r, (e_fit, T_fit, status) = raw(theta, data)
    final_loss = 0.5 * jnp.sum(r**2)
    if history is None:
        history = jnp.stack([loss(theta0, data), final_loss])[-1 if exact else 0 :]
    else:
        filled = jnp.arange(history.shape[0]) < iterations
        history = jnp.where(filled, history, final_loss)
    fitted = law_with(law, free, theta)
    converged = jnp.all(jnp.abs(r) <= target_tol) & jnp.all(status == Status.separated)
    stderr = None
    if options.has_sigma:
        covariance = jnp.linalg.pinv(jacobian.T @ jacobian)
        params = jnp.stack([fitted.parameters[k] for k in free])
        scale = jnp.where(
            jnp.asarray([k == "e_nominal" for k in free]), params * (1 - params), params
        )
        se = scale * jnp.sqrt(jnp.abs(jnp.diag(covariance)))
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
        converged=(converged & stopped) | (final_loss <= 1e-30),
        iterations=jnp.asarray(iterations),
        history=history,
        stderr=stderr,
        free=free,
        optimizer=optimizer if isinstance(optimizer, str) else type(optimizer).__name__,
    )
