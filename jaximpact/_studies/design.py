"""Design studies with gradients: a bumper, sensitivities, uncertainty, a drop.

- `bumper_design`: the stiffness `c` and damping `b1` of law 14 (`c x^1.5 + b1 x^0.5 v`)
  that minimise the peak force over a range of impact speeds while the maximum compression
  stays under a bound and the restitution under a target (optax, constraints by penalty).
  Several (bound, target) pairs run at once (vmapped): trade-off curves in one compilation.
- `jacobian_batch`, `sensitivity_map`: `de/dparam` and `dT/dparam` over a batch or a grid
  (forward-mode derivatives through the event-terminated solve).
- `propagate_uncertainty`: the spread of `e` and `T` from scattered parameters, to first
  order (`J Sigma J^T`) and by Monte Carlo over the same law (vmapped), with the Monte Carlo
  sampling error that says whether the two agree.
- `drop_design`: the drop height and mass that give a wanted sequence of bounce apexes
  (Levenberg-Marquardt through `jaximpact.bounce`, forward mode).
"""

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
from jaxtyping import Array

from .._batch.batch import _build_law, _cost_key, prepare_rows, run_batch
from .._fit.least_squares import levenberg_marquardt
from .._laws import LAWS, law as make_law
from .._solve.impact import impact
from .._status import Status
from .maps import C_RANGE, _axis

# ----------------------------------------------------------------------------- bumper


class BumperDesign(eqx.Module):
    """The result of `bumper_design` (SI units). With several bounds, every array has a
    leading axis over the pairs `(x_max_bound, e_target)`.

    - `c` (N/m^1.5), `b1` (N s/m^1.5): the design; `law(i)` builds the i-th one.
    - `speeds` (m/s), `m` (kg), `x_max_bound` (m), `e_target`: the specification.
    - `F_max` (N), `x_max` (m), `e`: at each speed (last axis), for the design.
    - `F_peak` (N): the largest `F_max` over the speeds (what was minimised).
    - `feasible`: every `x_max <= x_max_bound (1 + tol)` and `e <= e_target + tol`.
    - `history`: the penalised objective at each iteration.
    - `F_ideal` (N): the lower bound `m v_max^2 / (2 x_max_bound)` of any force law with
      that stroke (a constant force over the whole stroke).
    """

    c: Array
    b1: Array
    speeds: Array
    m: Array
    x_max_bound: Array
    e_target: Array
    F_max: Array
    x_max: Array
    e: Array
    F_peak: Array
    feasible: Array
    history: Array
    F_ideal: Array

    def law(self, index: int | None = None):
        """The designed law (`index`: which bound, when there are several)."""
        c, b1 = (self.c, self.b1) if index is None else (self.c[index], self.b1[index])
        return make_law("hertz_rate", c=float(c), b1=float(b1))


def _bumper_response(theta, scales, m, speeds, rtol):
    """`F_max`, `x_max`, `e` of law 14 with `(c, b1) = scales exp(theta)` at each speed."""
    c, b1 = scales[0] * jnp.exp(theta[0]), scales[1] * jnp.exp(theta[1])
    law = make_law("hertz_rate", c=c, b1=b1)

    def one(v0):
        r = impact(law, m=m, v0=v0, rtol=rtol)
        return jnp.stack([r.F_max, r.x_max, r.e])

    return jax.vmap(one)(speeds)


@functools.partial(jax.jit, static_argnames=("steps", "rtol"))
def _optimise_bumper(theta0, scales, m, speeds, bound, e_target, tol, lr, mu, steps, rtol):
    """Adam on `log(c / scales[0]), log(b1 / scales[1])`, the penalty weight growing
    geometrically from `mu[0]` to `mu[1]` (a continuation: first find the region, then
    sharpen the constraints) while the learning rate decays to 1% (to settle on the
    constraint boundary). Returns the parameters of the last evaluation, its response
    (`F_max, x_max, e` per speed) and the objective's history."""
    schedule = optax.cosine_decay_schedule(lr, steps, alpha=0.01)
    # clipped: the first (penalty-dominated) gradients must not freeze Adam's step size
    optimiser = optax.chain(optax.clip_by_global_norm(1.0), optax.adam(schedule, b2=0.99))

    def objective(theta, weight):
        response = _bumper_response(theta, scales, m, speeds, rtol)
        F, x, e = response.T
        peak = 0.01 * jax.nn.logsumexp(jnp.log(F) / 0.01)  # smooth max of log F_max
        over_x = jax.nn.relu(jnp.log(x / bound) + 0.5 * tol)
        over_e = jax.nn.relu((e - e_target + 0.5 * tol) / 0.01)
        value = peak + weight * (jnp.sum(over_x**2) + jnp.sum(over_e**2))
        return value, (value, response)

    def step(carry, k):
        theta, state = carry
        weight = mu[0] * (mu[1] / mu[0]) ** (k / (steps - 1))
        # forward mode (2 parameters), value and response from the same pass
        grad, (value, response) = jax.jacfwd(objective, has_aux=True)(theta, weight)
        updates, state = optimiser.update(grad, state, theta)
        return (optax.apply_updates(theta, updates), state), (value, theta, response)

    carry = (theta0, optimiser.init(theta0))
    _, (history, thetas, responses) = jax.lax.scan(step, carry, jnp.arange(steps))
    return thetas[-1], responses[-1], history


def bumper_design(
    *,
    m,
    speeds,
    x_max_bound,
    e_target,
    c0=None,
    b1_0=None,
    steps: int = 250,
    learning_rate: float = 0.05,
    penalty=(1.0, 1e4),
    tol: float = 1e-3,
    rtol: float = 1e-8,
) -> BumperDesign:
    """Choose `c` and `b1` of law 14 (`F = c x^1.5 + b1 x^0.5 v`, seed paper eq. 14) for a
    body of mass `m` (kg) hitting at every speed in `speeds` (m/s): minimise the peak
    contact force over the speeds, subject to `x_max <= x_max_bound` (m) and
    `e <= e_target` at every speed.

    Adam (optax) on `log c, log b1`, with gradients by forward mode through the solves; the
    constraints enter as quadratic penalties whose weight grows from `penalty[0]` to
    `penalty[1]` over the `steps` iterations (a continuation), with a margin of `tol/2` so
    that the final design meets them to `tol` (relative in `x_max`, absolute in `e`).
    `x_max_bound` and `e_target` may be 1-D arrays (broadcast together): all pairs are
    optimised at once (vmapped, one compilation), which gives trade-off curves such as the
    peak force against the stroke.
    `c0`, `b1_0`: starting point (default: the undamped spring that just reaches the bound
    at the highest speed, and a damping group of 0.5 at the mean speed).

    **Example**:
    `d = bumper_design(m=1.0, speeds=[1, 2, 3], x_max_bound=0.01, e_target=0.5)`;
    `d.c, d.b1, d.F_peak, d.feasible`.
    """
    speeds = jnp.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size < 1:
        raise ValueError("speeds must be a 1-D array of impact speeds (m/s)")
    if not np.all(np.asarray(speeds) > 0):
        raise ValueError("every impact speed must be > 0 m/s")
    bounds, targets = np.broadcast_arrays(
        np.asarray(x_max_bound, dtype=float), np.asarray(e_target, dtype=float)
    )
    if bounds.ndim > 1 or not np.all(bounds > 0):
        raise ValueError("x_max_bound must be a positive number or 1-D array (m)")
    if np.any(targets <= 0) or np.any(targets > 1):
        raise ValueError(f"e_target must lie in (0, 1], got {e_target}")
    if not float(m) > 0:
        raise ValueError(f"mass m must be > 0 kg, got {m}")
    m = jnp.asarray(m, dtype=float)
    v_max, v_mean = jnp.max(speeds), jnp.mean(speeds)

    def start(bound):
        c = 1.25 * m * v_max**2 / bound**2.5 if c0 is None else jnp.asarray(c0, dtype=float)
        x_star = (m * v_mean**2 / c) ** 0.4
        b1 = 0.5 * m * v_mean / x_star**1.5 if b1_0 is None else jnp.asarray(b1_0, dtype=float)
        return jnp.stack([c, b1])

    def solve(bound, target):
        scales = start(bound)
        theta, response, history = _optimise_bumper(
            jnp.zeros(2),
            scales,
            m,
            speeds,
            bound,
            target,
            tol,
            learning_rate,
            jnp.asarray(penalty, dtype=float),
            steps,
            rtol,
        )
        F, x, e = response.T
        design = scales * jnp.exp(theta)
        feasible = jnp.all(x <= bound * (1 + tol)) & jnp.all(e <= target + tol)
        return design, F, x, e, feasible, history

    solver = jax.vmap(solve) if bounds.ndim else solve
    design, F, x, e, feasible, history = solver(jnp.asarray(bounds), jnp.asarray(targets))
    return BumperDesign(
        c=design[..., 0],
        b1=design[..., 1],
        speeds=speeds,
        m=m,
        x_max_bound=jnp.asarray(bounds),
        e_target=jnp.asarray(targets),
        F_max=F,
        x_max=x,
        e=e,
        F_peak=jnp.max(F, axis=-1),
        feasible=feasible,
        history=history,
        F_ideal=m * v_max**2 / (2 * jnp.asarray(bounds)),
    )


# ----------------------------------------------------------------------------- sensitivities


@functools.lru_cache(maxsize=32)
def _jacobian_member(skeleton, wrt: tuple, options: tuple):
    """One row -> `e`, `T`, `status` and their forward-mode derivatives with respect to
    `wrt` (law parameters, `m`, `v0`); cached so that batches of one kind compile once."""
    keywords = dict(options)

    def member(row):
        def solve(theta):
            params = {**row["params"], **{k: v for k, v in theta.items() if k in row["params"]}}
            result = impact(
                _build_law(skeleton, params),
                m=theta.get("m", row["m"]),
                v0=theta.get("v0", row["v0"]),
                g=row.get("g", 0.0),
                peaks=False,
                **keywords,
            )
            values = jnp.stack([result.e, result.T])
            return values, (values, result.status)

        theta = {k: row["params"][k] if k in row["params"] else row[k] for k in wrt}
        jac, (values, status) = jax.jacfwd(solve, has_aux=True)(theta)
        out = {"e": values[0], "T": values[1], "status": status}
        for k in wrt:
            out[f"de_d{k}"], out[f"dT_d{k}"] = jac[k][0], jac[k][1]
        return out

    return member


def jacobian_batch(
    law,
    params: dict | None = None,
    *,
    wrt,
    m,
    v0,
    g=0.0,
    separation: str = "force",
    rtol: float = 1e-10,
    progress: bool = False,
    **batch_options,
) -> dict[str, np.ndarray]:
    """`e`, `T` and their derivatives with respect to `wrt` for a batch of impacts.

    `law`, `params`, `m`, `v0`, `g`, `separation`, `rtol`: as in `impact_batch`; `wrt`:
    names of law parameters and/or `"m"`, `"v0"`. Returns numpy arrays `e`, `T`, `status`
    and `de_d<name>`, `dT_d<name>` for each name (SI units: `dT_dc` in s per N/m^n).
    Forward mode (`jax.jacfwd` with diffrax's `ForwardMode`), about 2-4 solves per row.
    """
    wrt = tuple(wrt)
    skeleton, law_params, kinematics = prepare_rows(law, params, m=m, v0=v0, g=g)
    for name in wrt:
        if name not in law_params and name not in ("m", "v0"):
            raise ValueError(
                f"cannot differentiate with respect to {name!r}: the law's parameters are "
                f"{', '.join(law_params)} (or m, v0)"
            )
    rows = {"params": law_params, "m": kinematics["m"], "v0": kinematics["v0"]}
    if np.any(kinematics["g"] != 0):
        rows["g"] = kinematics["g"]
    options = tuple(sorted(dict(separation=separation, rtol=rtol).items()))
    member = _jacobian_member(skeleton, wrt, options)
    cost = _cost_key(skeleton, law_params, **kinematics)  # rows of similar step counts together
    return run_batch(
        member, rows, progress=progress, cost=cost, description="derivatives", **batch_options
    )


class SensitivityMap(eqx.Module):
    """`e`, `T` and their derivatives over a grid (rows: `damping`, columns: `c`).

    `de_dc`, `de_ddamping`, `dT_dc`, `dT_ddamping` in SI units; `elasticity(which)` gives
    the dimensionless `d ln y / d ln p` (the relative change of `y` per relative change of
    `p`), e.g. `elasticity("e", "c")`.
    """

    law: str = eqx.field(static=True)
    damping_name: str = eqx.field(static=True)
    c: np.ndarray
    damping: np.ndarray
    e: np.ndarray
    T: np.ndarray
    de_dc: np.ndarray
    de_ddamping: np.ndarray
    dT_dc: np.ndarray
    dT_ddamping: np.ndarray
    m: float
    v0: float
    fixed: dict

    def elasticity(self, output: str, parameter: str) -> np.ndarray:
        """`d ln output / d ln parameter` over the grid (`output` "e" or "T", `parameter`
        "c" or "damping")."""
        grids = np.meshgrid(self.damping, self.c, indexing="ij")
        value = {"damping": grids[0], "c": grids[1]}[parameter]
        derivative = getattr(self, f"d{output}_d{parameter}")
        return derivative * value / getattr(self, output)


def sensitivity_map(
    law_name: str,
    *,
    c=None,
    damping=None,
    m=1.0,
    v0=2.5,
    fixed: dict | None = None,
    num: int = 31,
    rtol: float = 1e-10,
    progress: bool = False,
    **batch_options,
) -> SensitivityMap:
    """`de/dc`, `de/d(damping)`, `dT/dc`, `dT/d(damping)` of `law_name` over the grid
    `damping x c`; the grid's defaults are those of `restitution_map` (the law's row:
    `damping`, `map_range`, `map_fixed`).

    **Example**: `s = sensitivity_map("hertz_rate"); s.elasticity("e", "damping")`.
    """
    spec = LAWS[law_name]
    damping_name = spec.damping
    fixed = dict(spec.map_fixed if fixed is None else fixed)
    c = _axis(c, C_RANGE, num, log=True)
    damping = _axis(damping, spec.map_range, num, log=False)
    d_grid, c_grid = np.meshgrid(damping, c, indexing="ij")
    params = {**fixed, "c": c_grid.ravel(), damping_name: d_grid.ravel()}
    out = jacobian_batch(
        law_name,
        params,
        wrt=("c", damping_name),
        m=m,
        v0=v0,
        rtol=rtol,
        progress=progress,
        **batch_options,
    )
    shape = d_grid.shape
    grid = {k: np.asarray(v).reshape(shape) for k, v in out.items()}
    return SensitivityMap(
        law=law_name,
        damping_name=damping_name,
        c=c,
        damping=damping,
        e=grid["e"],
        T=grid["T"],
        de_dc=grid["de_dc"],
        de_ddamping=grid[f"de_d{damping_name}"],
        dT_dc=grid["dT_dc"],
        dT_ddamping=grid[f"dT_d{damping_name}"],
        m=float(m),
        v0=float(v0),
        fixed=fixed,
    )


def plot_sensitivity(smap: SensitivityMap, *, fig=None, levels: int = 12, title=None):
    """Four contour plots of the elasticities `d ln e / d ln c`, `d ln e / d ln damping`,
    `d ln T / d ln c`, `d ln T / d ln damping` over the grid; returns the Figure."""
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(11, 8), layout="constrained")
    axes = fig.subplots(2, 2)
    x, y = np.meshgrid(smap.damping, smap.c, indexing="ij")
    for row, output in enumerate(("e", "T")):
        for col, parameter in enumerate(("c", "damping")):
            ax = axes[row, col]
            values = smap.elasticity(output, parameter)
            filled = ax.contourf(x, y, values, levels=levels, cmap="coolwarm")
            lines = ax.contour(x, y, values, levels=filled.levels, colors="k", linewidths=0.4)
            ax.clabel(lines, lines.levels[::2], fontsize=7, fmt="%.3g")
            name = smap.damping_name if parameter == "damping" else "c"
            fig.colorbar(filled, ax=ax, label=f"d ln {output} / d ln {name}")
            ax.set_yscale("log")
            ax.set_xlabel(smap.damping_name)
            ax.set_ylabel("stiffness $c$")
            ax.set_title(f"$\\partial \\ln {output} / \\partial \\ln {name}$")
    if title is None:
        title = f"{smap.law}: sensitivities of e and T (m = {smap.m:g} kg, v0 = {smap.v0:g} m/s)"
    fig.suptitle(title)
    return fig


# ----------------------------------------------------------------------------- uncertainty


class Uncertainty(eqx.Module):
    """First-order and Monte Carlo spread of `e` and `T` (index 0: `e`, 1: `T` in s).

    - `nominal`: `(e, T)` at the nominal parameters; `names`, `sigma`: the scattered inputs
      and their standard deviations; `jacobian`: `d(e, T)/d(names)`, shape `(2, k)`.
    - `std_linear`, `cov_linear`: `sqrt(diag(J Sigma J^T))` and `J Sigma J^T`.
    - `n_samples`, `mean_mc`, `std_mc`, `cov_mc`: the Monte Carlo estimates;
      `std_mc_error`, `mean_mc_error`: their standard errors (from the sample kurtosis,
      no normality assumed); `z_std = (std_linear - std_mc) / std_mc_error`: agreement
      within the sampling error means `|z_std| < 2` or so.
    - `separated_fraction`: Monte Carlo samples whose impact ended in separation.
    - `samples`: the sampled `(e, T)`, shape `(2, n_samples)`.
    """

    names: tuple = eqx.field(static=True)
    nominal: np.ndarray
    sigma: np.ndarray
    jacobian: np.ndarray
    std_linear: np.ndarray
    cov_linear: np.ndarray
    n_samples: int
    mean_mc: np.ndarray
    std_mc: np.ndarray
    cov_mc: np.ndarray
    std_mc_error: np.ndarray
    mean_mc_error: np.ndarray
    z_std: np.ndarray
    separated_fraction: float
    samples: np.ndarray


def propagate_uncertainty(
    law,
    *,
    m,
    v0,
    scatter: dict,
    n_samples: int = 20_000,
    seed: int = 0,
    separation: str = "force",
    rtol: float = 1e-10,
    progress: bool = False,
    **batch_options,
) -> Uncertainty:
    """Spread of `e` and `T` of `law` (hitting at `v0` m/s with mass `m` kg) when the inputs
    in `scatter` are independent normal variables with those standard deviations (SI units;
    keys: the law's parameters and/or `"m"`, `"v0"`).

    First order: `Sigma_out = J diag(sigma^2) J^T` with the Jacobian by forward mode at the
    nominal point. Monte Carlo: `n_samples` draws solved at once (in the same compiled batch
    as the nominal point's Jacobian: `jacobian_batch`), with the
    standard errors of the sample mean and standard deviation, so that `z_std` tells whether
    the first-order spread agrees with the sampled one within the sampling error (it
    departs when the scatter is large enough for the curvature of `e` and `T` to matter).
    Draws must stay physical (positive): the scatter must be a few percent, not tens.

    **Example**:
    `propagate_uncertainty(law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5,
    scatter={"c": 0.05 * 2e6, "b1": 0.1 * 800.0})`.
    """
    names = tuple(scatter)
    if not names:
        raise ValueError("scatter must give the standard deviation of at least one input")
    sigma = np.asarray([float(scatter[k]) for k in names])
    if np.any(~np.isfinite(sigma)) or np.any(sigma < 0):
        raise ValueError("standard deviations in scatter must be finite and >= 0")
    skeleton, params, kinematics = prepare_rows(law, None, m=m, v0=v0)
    nominal_inputs = {**{k: v[0] for k, v in params.items()}, "m": kinematics["m"][0]}
    nominal_inputs["v0"] = kinematics["v0"][0]
    unknown = [k for k in names if k not in nominal_inputs]
    if unknown:
        raise ValueError(f"cannot scatter {unknown}: choose from {sorted(nominal_inputs)}")

    # one batch: the nominal point (row 0: its Jacobian) and the draws (their values). The
    # draws' derivatives are computed too: that costs less than compiling a second program
    rng = np.random.default_rng(seed)
    draws = {
        k: np.concatenate(
            [[nominal_inputs[k]], nominal_inputs[k] + s * rng.standard_normal(n_samples)]
        )
        for k, s in zip(names, sigma, strict=True)
    }
    for k, values in draws.items():
        if np.any(values <= 0):
            raise ValueError(f"the scatter of {k} is too large: some draws are <= 0")
    out = jacobian_batch(
        law,
        {k: draws.get(k, v) for k, v in params.items()},
        wrt=names,
        m=draws.get("m", kinematics["m"]),
        v0=draws.get("v0", kinematics["v0"]),
        separation=separation,
        rtol=rtol,
        progress=progress,
        **batch_options,
    )
    nominal = np.array([out["e"][0], out["T"][0]])
    jac = np.array([[out[f"d{y}_d{k}"][0] for k in names] for y in ("e", "T")])
    cov_linear = jac @ np.diag(sigma**2) @ jac.T
    out = {k: v[1:] for k, v in out.items()}
    samples = np.stack([out["e"], out["T"]])
    mean, std = samples.mean(axis=1), samples.std(axis=1, ddof=1)
    centred = samples - mean[:, None]
    fourth = np.mean(centred**4, axis=1)
    n = n_samples
    var_of_var = (fourth - std**4 * (n - 3) / (n - 1)) / n
    std_error = np.sqrt(np.maximum(var_of_var, 0.0)) / (2 * std)
    std_linear = np.sqrt(np.diag(cov_linear))
    return Uncertainty(
        names=names,
        nominal=nominal,
        sigma=sigma,
        jacobian=jac,
        std_linear=std_linear,
        cov_linear=cov_linear,
        n_samples=n,
        mean_mc=mean,
        std_mc=std,
        cov_mc=np.cov(samples),
        std_mc_error=std_error,
        mean_mc_error=std / np.sqrt(n),
        z_std=(std_linear - std) / std_error,
        separated_fraction=float(np.mean(out["status"] == Status.separated)),
        samples=samples,
    )


# ----------------------------------------------------------------------------- drop design


class DropDesign(eqx.Module):
    """The result of `drop_design` (SI units).

    - `h0` (m), `m` (kg): the drop height and mass found.
    - `target`, `apexes` (m): the wanted and the achieved apex heights after each contact.
    - `residuals`: `ln(apexes / target)`; `loss`: half their sum of squares.
    - `converged`: the scaled gradient, the relative decrease or the step fell below `tol`
      (`_fit.least_squares`).
    - `iterations`; `history`: the loss at each accepted iterate.
    """

    h0: float
    m: float
    target: np.ndarray
    apexes: np.ndarray
    residuals: np.ndarray
    loss: float
    converged: bool
    iterations: int
    history: np.ndarray


@functools.partial(jax.jit, static_argnames=("count", "rtol"))
def _apex_residuals(theta, law, target, g, count, rtol):
    """`ln(apex_k / target_k)` for `theta = (ln h0, ln m)` and its Jacobian (forward mode),
    from `bounce`: the first `count` contacts, flights in closed form."""
    from .._solve.bounce import bounce

    def residuals(theta):
        h0, m = jnp.exp(theta[0]), jnp.exp(theta[1])
        # long enough for `count` flights, each shorter than the drop's own duration
        t_end = jax.lax.stop_gradient((2.0 * count + 2.0) * jnp.sqrt(2.0 * h0 / g))
        b = bounce(law, m=m, h0=h0, t_end=t_end, g=g, max_impacts=count, peaks=False, rtol=rtol)
        apexes = b.apex_heights[:count]
        r = jnp.log(apexes) - jnp.log(target)
        return r, (r, apexes)

    jac, (r, apexes) = jax.jacfwd(residuals, has_aux=True)(theta)
    return r, jac, apexes


def drop_design(
    law,
    *,
    apexes,
    h0_guess: float,
    m_guess: float,
    g: float = 9.81,
    max_iterations: int = 40,
    tol: float = 1e-10,
    rtol: float = 1e-10,
) -> DropDesign:
    """The drop height `h0` (m) and mass `m` (kg) of a ball released from rest on a floor
    with contact law `law` whose first bounces reach the wanted apex heights `apexes` (m,
    above the floor, one per contact, in order).

    Least squares in `ln(apex / target)` over `(ln h0, ln m)` by Levenberg-Marquardt, with
    the Jacobian by forward mode through `jaximpact.bounce` (closed-form flights, one impact
    solve with gravity per contact). The mass matters because the restitution of a law with
    a length scale depends on it (law 14: `e` is a function of `b1 (m v^2/c)^0.6 / (m v)`,
    so heavier balls bounce higher), the height because `e` depends on the impact speed.
    A sequence no `(h0, m)` can give returns the best fit, `converged` true and nonzero
    residuals: read `residuals`.

    **Example**: `drop_design(law("hertz_rate", c=1e6, b1=1350.0),
    apexes=[0.24, 0.10, 0.043], h0_guess=1.0, m_guess=0.3)`.
    """
    target = np.asarray(apexes, dtype=float)
    if target.ndim != 1 or target.size < 2 or np.any(target <= 0):
        raise ValueError("apexes must be at least two positive heights (m), one per bounce")
    if np.any(np.diff(target) >= 0):
        raise ValueError("apex heights must decrease from bounce to bounce")
    if not (h0_guess > target[0] and m_guess > 0):
        raise ValueError("h0_guess must be above the first apex and m_guess > 0")
    count = int(target.size)
    apex_residuals = functools.partial(
        _apex_residuals, law=law, target=jnp.asarray(target), g=float(g), count=count, rtol=rtol
    )

    def evaluate(theta):
        return tuple(np.asarray(out) for out in apex_residuals(jnp.asarray(theta)))

    theta0 = np.log([h0_guess, m_guess])
    fit = levenberg_marquardt(evaluate, theta0, max_iter=max_iterations, tol=tol)
    if not np.all(np.isfinite(fit.residuals)):
        raise ValueError(
            f"the starting guess (h0 = {h0_guess} m, m = {m_guess} kg) does not give {count} "
            "bounces: start higher or heavier"
        )
    return DropDesign(
        h0=float(np.exp(fit.theta[0])),
        m=float(np.exp(fit.theta[1])),
        target=target,
        apexes=np.asarray(fit.extra),
        residuals=fit.residuals,
        loss=float(fit.history[-1]),
        converged=bool(fit.converged),
        iterations=fit.iterations,
        history=fit.history,
    )
