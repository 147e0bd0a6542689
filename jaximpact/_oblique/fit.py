"""Fitting a tangential law to measured oblique rebounds: `fit_oblique`, Levenberg-Marquardt
(optimistix) on the logarithms of the free parameters from several starts (the given one
and the best minima of a log grid, whose losses are evaluated first), the impacts solved
with forward-mode derivatives through every stick-slip transition, standard errors from the
Jacobian, and the parameters the data do not bound, with their one-sided bounds, found by
probing the loss. One compiled program (`_evaluated`: residuals, Jacobian, impacts) serves
the grid, the optimiser (by a host callback from its loop) and the probes."""

import concurrent.futures
import functools
import itertools
import os
import warnings

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array

from .._checks import check_positive, is_traced
from .._compiling import quick_jit
from .._format import format_fields, format_value, jsonable
from .._laws import AbstractLaw
from .._solve.options import CUSTOM_RTOL, DEFAULT_RTOL
from .._solve.precision import resolvable_tolerances
from .._status import Status
from .._xla_log import quietly_compiled
from .impact import ObliqueInputs, ObliqueOptions, _check_laws, lever_share, solve_oblique
from .tangential import AbstractTangentialLaw
from .theory import rigid_oblique


class ObliqueFit(eqx.Module):
    """A fitted tangential law and how well it reproduces the rebounds.

    - `tangential`, `params`: the fitted law and its parameters (SI units); `free`: the
      parameters fitted; `stderr`: their standard errors from the Jacobian, each kind of
      residual (e_t, spin) scaled by its given sigma, else by its own scatter (the
      residuals of a kind over its share of the degrees of freedom); NaN without a degree
      of freedom, and NaN for a parameter the data do not bound (`undetermined`).
    - `undetermined`: free parameters the data do not bound on one side or both (the loss
      changes by less than a one-sided 95 % chi-square, 2.71 in units of the sigmas, when
      the parameter alone moves a factor 10 and 100 that way): e.g. `mu` where every
      impact sticks or micro-slips (a larger mu fits as well). `bounds`: for each of
      them `(lower, upper)`, the one-sided 95 % bound the data do give (the loss profiled
      over the stiffness or `mu`, the other free parameters held), None on an open side.
      `notes`: these findings in words, and another minimum that fits nearly as well.
    - `e_t`, `omega_out`: the predictions at every row (NaN where `v_t = 0` for `e_t`);
      `residuals`: `(e_t_fit - e_t) / sigma_e_t` then `(omega_fit - omega) / sigma_omega`
      (default sigmas: 1 for `e_t`, the largest measured `|omega_out|` for the spin); `loss`:
      half their sum of squares; `iterations` (of the start kept); `start_losses`: the loss
      each refined start ended at, the given start first; `converged`: the optimiser met
      its tolerance from the start kept, every fitted impact separated, and no point of
      the start grid has a lower loss than the fit (else a warning says by how much).
    - Goodness of fit, each kind of residual apart (their units differ): `n_data`
      (measured values fitted), `dof` (`n_data` less the free parameters), `rms_e_t`
      (root mean square of `e_t_fit - e_t`, NaN without `e_t`), `rms_omega` (the same for
      the spin, rad/s), `reduced_chi2_e_t` and `reduced_chi2_omega` (the kind's chi-square
      over its share of `dof`, `dof n_kind / n_data`; about 1 for a law that fits within
      the given sigma; NaN where that kind's sigma was not given); `reduced_chi2`
      (`2 loss / dof`) only where one kind was fitted (NaN where both were: it would add
      e_t and spin residuals; without sigmas it only compares fits).
    - What the fit was made of, so that `posterior` samples the same model: `problem`,
      the normal law, the start's tangential law, the sphere (`m` kg, `R` m, `inertia`,
      `g` m/s^2), the rows (`v_n`, `v_t` m/s, `omega` rad/s), the measured `e_t` and
      `omega_out` (rad/s; NaN where a row has none, all NaN for a kind not measured), the
      residuals' scales (`s_e`, `s_w`: the given sigmas or their defaults) and the solve's
      options; `sigma_e_t`, `sigma_omega`: the sigmas as given (None: not given). None in
      an `ObliqueFit` built by hand.
    """

    tangential: AbstractTangentialLaw
    params: dict[str, Array]
    stderr: dict[str, Array]
    e_t: Array
    omega_out: Array
    residuals: Array
    loss: Array
    converged: Array
    iterations: Array
    n_data: Array
    dof: Array
    rms_e_t: Array
    rms_omega: Array
    reduced_chi2: Array
    reduced_chi2_e_t: Array
    reduced_chi2_omega: Array
    start_losses: Array
    bounds: dict[str, tuple[float | None, float | None]]
    free: tuple[str, ...] = eqx.field(static=True)
    weighted: bool = eqx.field(static=True, default=False)
    undetermined: tuple[str, ...] = eqx.field(static=True, default=())
    notes: tuple[str, ...] = eqx.field(static=True, default=())
    problem: eqx.Module | None = None
    sigma_e_t: Array | None = None
    sigma_omega: Array | None = None

    def summary(self) -> str:
        units = {k: "" if u == "-" else u for k, u in self.tangential.spec.units.items()}
        rows = []
        for k in self.free:
            unit = units.get(k, "")
            if k in self.undetermined:
                rows.append(
                    (
                        k,
                        f"{format_value(self.params[k], unit)} "
                        f"({_bound_text(self.bounds.get(k), unit)})",
                    )
                )
                continue
            rows.append(
                (k, f"{format_value(self.params[k], unit)} ± {format_value(self.stderr[k], unit)}")
            )
        fixed = [k for k in self.params if k not in self.free]
        rows += [(k, f"{format_value(self.params[k], units.get(k, ''))} (fixed)") for k in fixed]
        rows += [
            ("rms e_t", format_value(self.rms_e_t)),
            ("rms omega", format_value(self.rms_omega, "rad/s")),
        ]
        kinds = (
            ("e_t", self.rms_e_t, self.reduced_chi2_e_t),
            ("omega", self.rms_omega, self.reduced_chi2_omega),
        )
        for kind, rms, reduced in kinds:
            if np.isnan(float(rms)):  # not measured
                continue
            text = format_value(reduced)
            if np.isnan(float(reduced)):
                text = f"- (no sigma_{kind}: its scale is the residuals' own)"
            rows.append((f"reduced chi2 {kind}", text))
        losses = ", ".join(format_value(v) for v in np.atleast_1d(self.start_losses))
        rows += [
            ("n_data, dof", f"{int(self.n_data)}, {int(self.dof)}"),
            ("converged", format_value(self.converged)),
            ("iterations", format_value(self.iterations, None)),
            ("starts", f"{np.size(self.start_losses)}, losses {losses}"),
        ]
        text = format_fields(f"ObliqueFit of {self.tangential.name!r} (SI units)", rows)
        return "\n".join([text, *(f"  note: {note}" for note in self.notes)])

    def to_dict(self) -> dict:
        """The fit as plain numbers and lists (SI units), NaN as None: `tangential` (name
        and parameters), `params`, `stderr`, `free`, `undetermined`, `bounds`, `notes`,
        the goodness of fit, `start_losses`, per row `e_t`, `omega_out`, and `residuals`.
        Concrete fits only (not inside `jit`)."""
        names = (
            "params",
            "stderr",
            "e_t",
            "omega_out",
            "residuals",
            "loss",
            "converged",
            "iterations",
            "n_data",
            "dof",
            "rms_e_t",
            "rms_omega",
            "reduced_chi2",
            "reduced_chi2_e_t",
            "reduced_chi2_omega",
            "start_losses",
        )
        out = {k: jsonable(getattr(self, k)) for k in names}
        tangential = {"name": self.tangential.name, "parameters": out["params"]}
        return {
            "tangential": tangential,
            **out,
            "free": list(self.free),
            "weighted": self.weighted,
            "undetermined": list(self.undetermined),
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "notes": list(self.notes),
        }

    def __repr__(self) -> str:
        return self.summary()


def _bound_text(bound, unit) -> str:
    if bound is None:
        return "not determined by these data"
    lower, upper = bound
    if lower is None and upper is None:
        return "not bounded by these data"
    if upper is None:
        return f"bounded below only: >= {format_value(lower, unit)}"
    if lower is None:
        return f"bounded above only: <= {format_value(upper, unit)}"
    return f"between {format_value(lower, unit)} and {format_value(upper, unit)}"


def stiffness_name(tangential: AbstractTangentialLaw) -> str:
    """The tangential law's stiffness parameter (`kt`, `G_star`): the one its row requires
    to be > 0 (`TangentialSpec.positive`)."""
    (name,) = tangential.spec.positive
    return name


def default_free(tangential: AbstractTangentialLaw) -> tuple[str, ...]:
    """What `fit_oblique` and `jaximpact fit-oblique` fit unless told: the row's stiffness
    (`kt` or `G_star`) and `mu`."""
    return (stiffness_name(tangential), "mu")


def _rows(name, value, n):
    array = jnp.asarray(value, dtype=float)
    if array.ndim > 1:
        raise ValueError(f"{name} must be a number or a 1-D array, got shape {array.shape}")
    if array.ndim == 1 and array.shape[0] != n:
        raise ValueError(f"{name} has {array.shape[0]} values where v_n has {n}")
    return jnp.broadcast_to(array, (n,))


def _with(tangential, free, theta):
    params = dict(tangential.params)
    params.update({k: jnp.exp(theta[i]) for i, k in enumerate(free)})
    return eqx.tree_at(lambda item: item.params, tangential, params)


class _Problem(eqx.Module):
    """The rows, the laws and the solve's options: what every compiled part of a fit takes
    (its arrays traced, so one program serves every start and probe)."""

    law: AbstractLaw
    tangential: AbstractTangentialLaw
    m: Array
    R: Array
    inertia: Array
    g: Array
    v_n: Array
    v_t: Array
    omega: Array
    e_t: Array
    omega_out: Array
    s_e: Array
    s_w: Array
    options: ObliqueOptions
    free: tuple[str, ...] = eqx.field(static=True)
    has_e: bool = eqx.field(static=True)
    has_w: bool = eqx.field(static=True)

    def predict(self, theta):
        fitted = _with(self.tangential, self.free, theta)

        def one(vn, vt, om):
            inputs = ObliqueInputs(self.m, self.R, vn, vt, om, self.inertia, self.g)
            return solve_oblique(self.law, fitted, inputs, self.options)

        return jax.vmap(one)(self.v_n, self.v_t, self.omega)

    def residuals(self, result):
        """`(e_t part, spin part)` of the residuals (zeros where not measured), concatenated."""
        parts = []
        if self.has_e:
            known = jnp.isfinite(self.e_t)
            target = jnp.where(known, self.e_t, 0.0)
            parts.append(jnp.where(known, (result.e_t - target) / self.s_e, 0.0))
        if self.has_w:
            known = jnp.isfinite(self.omega_out)
            target = jnp.where(known, self.omega_out, 0.0)
            parts.append(jnp.where(known, (result.omega_out - target) / self.s_w, 0.0))
        return jnp.concatenate(parts)


# the grid of starts: the stiffness over two decades either side of the start, `mu` over
# one decade either side (9 values); the best `max_starts - 1` of the grid's local minima
# are refined beside the given start
_STIFFNESS_DECADES = 2.0
_MU_DECADES = 1.0
_MU_SCAN = 9
# a one-sided 95 % bound: chi-square of one degree of freedom at 90 %
_CHI2_BOUND = 2.705543454095404
# a second minimum is reported where its loss is within this factor of the fit's
_NEAR = 2.0


def _evaluate(problem, thetas):
    """The residuals at each theta (rows of `thetas`) and whether every impact separated:
    `_evaluated` row by row, so that a fit compiles its solves once (a batched program of
    its own, values only, compiled for 30 s more), the rows after the first in threads,
    one per core."""

    def one(theta):
        r, _, result = _evaluated(problem, jnp.asarray(theta))
        return np.asarray(r), bool(np.all(np.asarray(result.status) == Status.separated))

    done = _in_threads(one, list(np.asarray(thetas, dtype=float)))
    return np.stack([r for r, _ in done]), np.array([ok for _, ok in done])


def _in_threads(fun, items) -> list:
    """`[fun(x) for x in items]`, the first in this thread (it compiles what the others
    run), the others in threads, one per core, each with the caller's float width."""
    x64 = jnp.result_type(float) == jnp.float64

    def one(item):
        with jax.enable_x64(x64):
            return fun(item)

    done = [one(items[0])]
    if len(items) > 1:
        workers = min(len(items) - 1, os.cpu_count() or 1)
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            done += list(pool.map(one, items[1:]))
    return done


@functools.partial(quick_jit, optimised=True)
def _evaluated(problem, theta):
    """The residuals at `theta`, their Jacobian (forward mode, exact across the stick-slip
    transitions) and the impacts: the one compiled program of a refinement (compiled
    quickly, `_compiling`: each call runs for milliseconds, a fit makes hundreds)."""

    def with_aux(t):
        result = problem.predict(t)
        r = problem.residuals(result)
        return r, (r, result)

    jacobian, (r, result) = jax.jacfwd(with_aux, has_aux=True)(theta)
    return r, jacobian, result


# the problems a refinement's compiled loop calls back for, by token (`_refine`)
_PROBLEMS: dict[int, _Problem] = {}
_TOKENS = itertools.count()


def _residuals_and_jacobian(token, theta):
    """Host side of the callback: `_evaluated`'s residuals and Jacobian (numpy). A callback
    runs with the default device set, which would key a second trace and compile of
    `_evaluated` apart from the calls outside it: it is unset here."""
    with jax.default_device(None):
        r, jacobian, _ = _evaluated(_PROBLEMS[int(token)], jnp.asarray(np.asarray(theta)))
    return np.asarray(r), np.asarray(jacobian)


@eqx.filter_jit
def _levenberg_marquardt(token, start, n_residuals: int, max_steps: int, tol):
    """optimistix's Levenberg-Marquardt from `start`, each evaluation of the residuals and
    their Jacobian a host callback to `_evaluated`: this loop compiles in a moment, and
    the solves compile once, in `_evaluated` (inside the loop they compiled twice)."""
    shapes = (
        jax.ShapeDtypeStruct((n_residuals,), start.dtype),
        jax.ShapeDtypeStruct((n_residuals, start.size), start.dtype),
    )

    @jax.custom_jvp
    def residuals(theta):
        return jax.pure_callback(_residuals_and_jacobian, shapes, token, theta)[0]

    @residuals.defjvp
    def _jvp(primals, tangents):
        r, jacobian = jax.pure_callback(_residuals_and_jacobian, shapes, token, primals[0])
        return r, jacobian @ tangents[0]

    solution = optx.least_squares(
        lambda theta, _: residuals(theta),
        optx.LevenbergMarquardt(rtol=tol, atol=tol),
        start,
        max_steps=max_steps,
        throw=False,
    )
    ok = solution.result == optx.RESULTS.successful
    return solution.value, ok, solution.stats["num_steps"]


def _refine(problem, start, max_steps, tol):
    """Levenberg-Marquardt from `start`: the parameters, whether it met `tol`, its steps,
    and there the residuals, their Jacobian and the impacts."""
    token = next(_TOKENS)
    _PROBLEMS[token] = problem
    try:
        theta, ok, steps = _levenberg_marquardt(
            jnp.asarray(token, dtype=jnp.int32),
            jnp.asarray(start),
            _residual_count(problem),
            max_steps,
            tol,
        )
    finally:
        del _PROBLEMS[token]
    theta = np.asarray(theta)
    r, jacobian, result = _evaluated(problem, jnp.asarray(theta))
    return theta, ok, steps, (r, jacobian, result)


def _residual_count(problem) -> int:
    return (int(problem.has_e) + int(problem.has_w)) * int(problem.v_n.shape[0])


def _chi2_parts(problem, thetas) -> tuple[np.ndarray, np.ndarray]:
    """For each row of `thetas` (numpy, any count): the sum of squared residuals of each
    kind, shape (count, kinds), inf where an impact did not separate or a residual is not
    finite."""
    thetas = np.atleast_2d(np.asarray(thetas, dtype=float))
    kinds = int(problem.has_e) + int(problem.has_w)
    r, separated = _evaluate(problem, thetas)
    chi2 = np.sum(np.asarray(r).reshape(thetas.shape[0], kinds, -1) ** 2, axis=-1)
    chi2[~np.asarray(separated) | ~np.all(np.isfinite(chi2), axis=-1)] = np.inf
    return chi2


def _final_chi2(r, result) -> float:
    """The sum of squared residuals where a refined start ended (inf where an impact did not
    separate or a residual is not finite: such an end is not kept)."""
    chi2 = float(np.sum(np.asarray(r) ** 2))
    separated = bool(np.all(np.asarray(result.status) == Status.separated))
    return chi2 if separated and np.isfinite(chi2) else np.inf


def _grid(theta0, free, stiffness, scan):
    """The start grid (log parameters, one row per point) and its shape: the stiffness and
    `mu` where free (the others at the start)."""
    axes = [np.array([float(t)]) for t in theta0]
    if stiffness in free:
        k = free.index(stiffness)
        axes[k] = theta0[k] + np.log(10.0) * np.linspace(-1.0, 1.0, scan) * _STIFFNESS_DECADES
    if "mu" in free:
        j = free.index("mu")
        axes[j] = theta0[j] + np.log(10.0) * np.linspace(-1.0, 1.0, _MU_SCAN) * _MU_DECADES
    shape = tuple(a.size for a in axes)
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(free))
    return points, shape


def _local_minima(losses, shape) -> np.ndarray:
    """Indices of the grid points no higher than any neighbour (diagonals included), lowest
    first."""
    grid = losses.reshape(shape)
    padded = np.pad(grid, 1, constant_values=np.inf)
    lowest = np.full(grid.shape, np.inf)
    for offset in np.ndindex(*(3,) * grid.ndim):
        if all(o == 1 for o in offset):
            continue
        window = tuple(slice(o, o + s) for o, s in zip(offset, grid.shape, strict=True))
        lowest = np.minimum(lowest, padded[window])
    minima = np.flatnonzero((grid <= lowest) & np.isfinite(grid))
    return minima[np.argsort(grid.ravel()[minima])]


def _rms(differences):
    """Root mean square over the finite entries (the rows measured)."""
    known = jnp.isfinite(differences)
    count = jnp.maximum(jnp.sum(known), 1)
    return jnp.sqrt(jnp.sum(jnp.where(known, differences, 0.0) ** 2) / count)


@quietly_compiled
def fit_oblique(
    law: AbstractLaw,
    tangential: AbstractTangentialLaw,
    *,
    m,
    R,
    v_n,
    v_t,
    omega=0.0,
    e_t=None,
    omega_out=None,
    sigma_e_t=None,
    sigma_omega=None,
    free=None,
    inertia=0.4,
    g=0.0,
    separation: str = "force",
    contact_point="surface",
    rtol: float | None = None,
    max_steps: int = 100,
    tol: float = 1e-10,
    start_scan: int = 17,
    max_starts: int = 4,
) -> ObliqueFit:
    """Fit the tangential law's `free` parameters to measured rebounds (SI units): the
    centre's tangential restitution `e_t` and/or the spin after `omega_out` (rad/s) of
    impacts with normal and tangential speeds `v_n`, `v_t` (m/s; arrays, one row per
    impact) and spin `omega` (rad/s) of a sphere `m` (kg), `R` (m), its normal contact
    `law` (held fixed: fit it first from head-on impacts with `calibrate`).

    `tangential` is the start; its free parameters (default `default_free(tangential)`:
    the row's stiffness, `kt` or `G_star`, and `mu`; from `kt`, `mu`, `ct`, `G_star`,
    `beta`) must be > 0 there and stay so (the fit moves their logarithms). The loss has
    one minimum per phase of the tangential oscillation in a sticking contact (Chung &
    Ooi's Test 4 e_t from kt = 3e6, mu = 0.2 stopped at kt = 6.3e6, mu = 0.114, rms e_t
    0.088, where kt = 9.4e7, mu = 0.093 gives 0.0071), so the fit first evaluates the loss
    on a log grid, `start_scan` stiffnesses over two decades either side of the start
    by nine friction coefficients over one decade either side (where free; no
    optimiser), then runs Levenberg-Marquardt (optimistix, to `tol` within
    `max_steps`) from the given start and from the lowest `max_starts - 1` local minima
    of the grid, and keeps the lowest loss. `start_scan=0` starts from `tangential`
    alone. A grid point below the fit's loss (a start that was not refined) makes
    `converged` False with a warning. The impacts are solved with forward-mode
    derivatives and landed events (`oblique_impact(..., land_events=True)`), so the
    Jacobian is exact across the stick-slip transitions.

    Each free parameter is then moved alone a factor 10 and 100 either way: where the
    loss rises by less than a one-sided 95 % chi-square (2.71 in units of the sigmas, or
    of the residuals' own scatter) the data do not bound it that way, e.g. `mu` where
    every impact sticks or micro-slips (a larger mu fits as well: only a lower bound).
    Such a parameter is listed in `undetermined`, its standard error is NaN, its
    one-sided bound (the loss profiled over the stiffness or `mu`) is in `bounds`, and
    `notes` (printed by `summary`) and a warning say so.

    A row with NaN in `e_t` (or in `omega_out`) is left out of that part. `separation`
    and `contact_point` (where the tangential force acts: `oblique_impact`'s; fit with the
    engine's, e.g. `"midpoint"` for LIGGGHTS, to export the fitted law to it) as in
    `oblique_impact`. Concrete inputs only (not inside `jit` or `vmap`).

    **Example**: `fit_oblique(law, tangential_law("linear_history", kt=1e7, mu=0.2),
    m=2.6e-4, R=2.5e-3, v_n=vns, v_t=vts, e_t=measured)`.
    """
    _check_laws(law, tangential)
    if e_t is None and omega_out is None:
        raise ValueError("fit_oblique needs measured e_t or omega_out (or both)")
    if free is None:
        free = default_free(tangential)
    free = (free,) if isinstance(free, str) else tuple(free)
    unknown = [k for k in free if k not in tangential.params]
    if unknown or not free:
        raise ValueError(
            f"free must name parameters of the tangential law {tangential.name!r} "
            f"({', '.join(tangential.params)}), got {', '.join(unknown) or 'none'}"
        )
    for k in free:
        check_positive(f"the start value of {k}", tangential.params[k])
    m = check_positive("mass m", m, "kg")
    R = check_positive("radius R", R, "m")
    inputs = (m, R, v_n, v_t, omega, e_t, omega_out, sigma_e_t, sigma_omega, inertia, g)
    if any(is_traced(a) for a in inputs) or any(is_traced(v) for v in tangential.params.values()):
        raise ValueError(
            "fit_oblique takes concrete inputs (not traced inside jit, vmap or grad): it "
            "chooses its starts and probes its bounds in Python"
        )
    v_n = jnp.atleast_1d(jnp.asarray(check_positive("normal speed v_n", v_n, "m/s"), float))
    if v_n.ndim != 1:
        raise ValueError(f"v_n must be a 1-D array of speeds, got shape {v_n.shape}")
    n = v_n.shape[0]
    v_t = _rows("v_t", v_t, n)
    omega = _rows("omega", omega, n)
    has_e, has_w = e_t is not None, omega_out is not None
    e_t = _rows("e_t", e_t if has_e else jnp.nan, n)
    omega_out = _rows("omega_out", omega_out if has_w else jnp.nan, n)
    if has_w and not np.any(np.isfinite(np.asarray(omega_out))):
        raise ValueError("omega_out has no finite value")
    s_e = _rows("sigma_e_t", 1.0 if sigma_e_t is None else sigma_e_t, n)
    scale_w = jnp.nanmax(jnp.abs(omega_out)) if has_w else 1.0
    s_w = _rows("sigma_omega", scale_w if sigma_omega is None else sigma_omega, n)
    if rtol is None:
        rtol = DEFAULT_RTOL if law.spec is not None else CUSTOM_RTOL
    rtol, atol, rest_tol = resolvable_tolerances(rtol, rtol, 1e-7)
    options = ObliqueOptions(
        separation=separation,
        solver=dfx.Tsit5(),
        adjoint=dfx.ForwardMode(),
        rtol=float(rtol),
        atol=float(atol),
        max_steps=4096,
        max_segments=16,
        tau_max=1e4,
        rest_tol=rest_tol,
        land=True,
        lever_share=lever_share(contact_point),
    )
    m, R, inertia, g = (jnp.asarray(a, dtype=float) for a in (m, R, inertia, g))
    problem = _Problem(
        law=law,
        tangential=tangential,
        m=m,
        R=R,
        inertia=inertia,
        g=g,
        v_n=v_n,
        v_t=v_t,
        omega=omega,
        e_t=e_t,
        omega_out=omega_out,
        s_e=s_e,
        s_w=s_w,
        options=options,
        free=free,
        has_e=has_e,
        has_w=has_w,
    )
    stiffness = stiffness_name(tangential)
    theta0 = np.array([np.log(float(tangential.params[k])) for k in free])

    # the starts: the given one, then the grid's lowest local minima
    starts = [theta0]
    grid_losses = np.array([])
    if start_scan and (stiffness in free or "mu" in free):
        points, shape = _grid(theta0, free, stiffness, start_scan)
        grid_losses = np.sum(_chi2_parts(problem, points), axis=-1)
        minima = [i for i in _local_minima(grid_losses, shape) if np.any(points[i] != theta0)]
        starts += [points[i] for i in minima[: max(max_starts - 1, 0)]]
    found = _in_threads(lambda s: _refine(problem, np.asarray(s), max_steps, tol), starts)
    values = np.stack([np.asarray(v) for v, _, _, _ in found])
    finals = np.array([_final_chi2(r, result) for _, _, _, (r, _, result) in found])
    pick = int(np.argmin(finals))
    theta = values[pick]
    _, ok, steps, (r, jacobian, result) = found[pick]
    r, jacobian = np.asarray(r), np.asarray(jacobian)
    loss = 0.5 * float(np.sum(r**2))
    converged = bool(ok) and bool(np.all(np.asarray(result.status) == Status.separated))
    fitted = _with(tangential, free, jnp.asarray(theta))
    units = tangential.spec.units
    notes = []

    def shown(point):
        return ", ".join(
            f"{k} = {format_value(np.exp(v), '' if units.get(k, '-') == '-' else units[k])}"
            for k, v in zip(free, point, strict=True)
        )

    below = np.flatnonzero(grid_losses < 2.0 * loss * (1.0 - 1e-9) - 1e-300)
    if below.size:
        best = below[np.argmin(grid_losses[below])]
        converged = False
        said = (
            f"a start that was not refined ({shown(points[best])}) has loss "
            f"{0.5 * grid_losses[best]:.4g}, lower than the fit's {loss:.4g} by "
            f"{loss - 0.5 * grid_losses[best]:.3g}: the fit is not the global minimum; "
            "start from there (or raise max_starts)"
        )
        notes.append(said)
        warnings.warn(said, stacklevel=2)
    others = [i for i in np.argsort(finals) if i != pick and np.isfinite(finals[i])]
    for i in others:  # another minimum (a distinct place) that fits nearly as well
        apart = np.max(np.abs(values[i] - theta)) > np.log(1.5)
        if apart and 0.5 * finals[i] <= _NEAR * loss and 0.5 * finals[i] > loss:
            notes.append(
                f"another minimum fits nearly as well: {shown(values[i])} (loss "
                f"{0.5 * finals[i]:.4g} against {loss:.4g}); more data at other incidences "
                "would tell them apart"
            )
            break

    # goodness of fit and standard errors, each kind of residual apart
    kinds = [
        (name, given)
        for name, has, given in (
            ("e_t", has_e, sigma_e_t is not None),
            ("omega", has_w, sigma_omega is not None),
        )
        if has
    ]
    measured = [values_ for values_, has in ((e_t, has_e), (omega_out, has_w)) if has]
    n_kind = np.array([int(np.sum(np.isfinite(np.asarray(v)))) for v in measured])
    n_data = int(np.sum(n_kind))
    dof = n_data - len(free)
    r_kind = r.reshape(len(kinds), n)
    chi2_kind = np.sum(r_kind**2, axis=-1)
    dof_kind = n_kind * dof / max(n_data, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        own = np.where(dof_kind > 0, chi2_kind / dof_kind, np.nan)  # each kind's variance
    reduced = {name: (float(own[i]) if given else np.nan) for i, (name, given) in enumerate(kinds)}
    # the scale of each kind: its sigma where given, else its own scatter (floored, so that
    # an exact fit does not divide by zero)
    variance = np.array(
        [1.0 if given else max(own[i], 1e-24) for i, (_, given) in enumerate(kinds)]
    )
    weights = np.repeat(1.0 / np.sqrt(variance), n)
    scaled = jacobian * weights[:, None]
    covariance = np.linalg.pinv(scaled.T @ scaled)
    se = np.exp(theta) * np.sqrt(np.abs(np.diag(covariance)))
    weighted = sigma_e_t is not None or sigma_omega is not None
    if not all(given for _, given in kinds):
        se = np.where(dof > 0, se, np.nan)

    # what the data do not bound: each parameter moved alone, a factor 10 and 100 each way
    undetermined, bounds = [], {}
    if np.all(np.isfinite(variance)) and np.isfinite(loss):
        chi2_at_fit = float(np.sum(chi2_kind / variance))
        factors = np.log(10.0) * np.array([1.0, 2.0, -1.0, -2.0])
        probes = np.repeat(theta[None], len(free) * 4, axis=0)
        for i in range(len(free)):
            probes[4 * i : 4 * i + 4, i] += factors
        rises = _chi2_parts(problem, probes) / variance
        rises = np.sum(rises, axis=-1).reshape(len(free), 4) - chi2_at_fit
        for i, k in enumerate(free):
            open_up = bool(np.all(rises[i, :2] < _CHI2_BOUND))
            open_down = bool(np.all(rises[i, 2:] < _CHI2_BOUND))
            if not (open_up or open_down):
                continue
            undetermined.append(k)
            se[i] = np.nan
            bounds[k] = _profile_bound(
                problem, theta, free, i, stiffness, variance, chi2_at_fit, open_up, open_down
            )
            said = _undetermined_note(
                k, bounds[k], open_up, open_down, units, fitted, result, problem
            )
            notes.append(said)
            warnings.warn(said, stacklevel=2)

    e_pred, w_pred = np.asarray(result.e_t), np.asarray(result.omega_out)
    return ObliqueFit(
        n_data=jnp.asarray(n_data),
        dof=jnp.asarray(dof),
        rms_e_t=_rms(e_pred - e_t) if has_e else jnp.asarray(jnp.nan),
        rms_omega=_rms(w_pred - omega_out) if has_w else jnp.asarray(jnp.nan),
        reduced_chi2=jnp.asarray(
            float(np.sum(chi2_kind)) / dof if len(kinds) == 1 and dof > 0 else np.nan
        ),
        reduced_chi2_e_t=jnp.asarray(reduced.get("e_t", np.nan)),
        reduced_chi2_omega=jnp.asarray(reduced.get("omega", np.nan)),
        weighted=weighted,
        tangential=fitted,
        params=fitted.parameters,
        stderr={k: jnp.asarray(se[i]) for i, k in enumerate(free)},
        e_t=result.e_t,
        omega_out=result.omega_out,
        residuals=jnp.asarray(r),
        loss=jnp.asarray(loss),
        converged=jnp.asarray(converged),
        iterations=steps,
        start_losses=jnp.asarray(0.5 * finals),
        bounds=bounds,
        undetermined=tuple(undetermined),
        notes=tuple(notes),
        free=free,
        problem=problem,
        sigma_e_t=None if sigma_e_t is None else s_e,
        sigma_omega=None if sigma_omega is None else s_w,
    )


def _profile_bound(problem, theta, free, i, stiffness, variance, chi2_at_fit, open_up, open_down):
    """`(lower, upper)`: the one-sided 95 % bound of free parameter `i` on the side the data
    bound (None on an open side): where the loss, profiled over the stiffness or `mu` (the
    partner, if free; on a grid a factor 3 either way) with the other parameters held,
    first rises by `_CHI2_BOUND` along a sweep of two decades from the fit."""
    if open_up and open_down:
        return None, None
    sense = -1.0 if open_up else 1.0  # sweep towards the bounded side
    steps = np.log(10.0) * np.linspace(0.125, 2.0, 16) * sense
    partners = [j for j, k in enumerate(free) if j != i and k in (stiffness, "mu")]
    offsets = np.log(3.0) * np.linspace(-1.0, 1.0, 9) if partners else np.zeros(1)
    points = np.repeat(theta[None], steps.size * offsets.size, axis=0)
    points[:, i] += np.repeat(steps, offsets.size)
    if partners:
        points[:, partners[0]] += np.tile(offsets, steps.size)
    chi2 = np.sum(_chi2_parts(problem, points) / variance, axis=-1)
    rise = np.min(chi2.reshape(steps.size, offsets.size), axis=-1) - chi2_at_fit
    crossed = np.flatnonzero(rise >= _CHI2_BOUND)
    if not crossed.size:
        bound = None  # not bounded within two decades either
    else:
        k = crossed[0]
        before_step, before_rise = (0.0, 0.0) if k == 0 else (steps[k - 1], rise[k - 1])
        share = (_CHI2_BOUND - before_rise) / max(rise[k] - before_rise, 1e-300)
        bound = float(np.exp(theta[i] + before_step + share * (steps[k] - before_step)))
    return (bound, None) if open_up else (None, bound)


def _undetermined_note(name, bound, open_up, open_down, units, fitted, result, problem):
    """What the data say of a parameter they do not bound, in words."""
    unit = "" if units.get(name, "-") == "-" else units[name]
    value = format_value(fitted.params[name], unit)
    if open_up and open_down:
        return (
            f"{name} is not determined by these data: moving it alone a factor 100 either "
            f"way changes the fit by less than the noise; {value} is not an estimate (hold it: "
            "free=...)"
        )
    side = "larger" if open_up else "smaller"
    why = ""
    if name == "mu" and open_up:
        rigid = rigid_oblique(
            mu=fitted.params["mu"],
            e=result.e,
            v_n=problem.v_n,
            v_t=problem.v_t,
            R=problem.R,
            omega=problem.omega,
            inertia=problem.inertia,
        )
        sliding = int(np.sum(np.asarray(rigid["sliding"])))
        why = (
            " (no impact slides throughout at the fitted mu: each sticks or micro-slips)"
            if sliding == 0
            else f" ({sliding} of {problem.v_n.shape[0]} impacts slide throughout)"
        )
    limit = _bound_text(bound, unit)
    if bound == (None, None):  # the sweep towards the bounded side never crossed
        limit = f"no {'lower' if open_up else 'upper'} bound within a factor 100 either"
    return (
        f"{name} is bounded on one side only{why}: a {side} {name} fits as well, so "
        f"{name} = {value} is not an estimate and has no standard error; {limit} "
        "(one-sided 95 %)"
    )
