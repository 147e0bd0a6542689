"""Which law do the measurements support? Fit them all and rank them."""

import concurrent.futures
import dataclasses
import math
import os
import warnings

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.special import gammaln

from .._format import format_fields, format_value, jsonable
from .._laws import LAWS, AbstractLaw, exponents, law
from .._progress import AbstractMeter, metered
from .._xla_log import quietly_compiled
from .calibrate import Fit, calibrate
from .parameters import default_free

# the laws `compare_laws` fits by default: every row with an equation that needs no geometry
# (a law with a radius, JKR's, takes part as a law object built with it)
PAPER_LAWS = tuple(
    name for name, spec in LAWS.items() if spec.equation != "-" and not spec.geometry
)


def _undamped_tau(n: float) -> float:
    """Contact time of `F = c x^n` in units of `t* = x*/v0`, `x* = (m v0^2/c)^(1/(n+1))`."""
    k = 1.0 / (n + 1.0)
    beta = math.exp(float(gammaln(k) + gammaln(0.5) - gammaln(k + 0.5)))
    return 2.0 * ((n + 1.0) / 2.0) ** k * beta / (n + 1.0)


def starting_law(name: str, *, m: float, v0: float, e: float, T: float | None, **geometry):
    """A law `name` whose parameters roughly reproduce `e` and `T` at speed `v0`: the
    undamped contact time sets `c`, an equivalent linear damping ratio sets the rest
    (`calibrate` then refines them); a row with its own start (`LawSpec.start`: Thornton's,
    JKR's) uses it. `geometry`: the law's geometry parameters (JKR's radius `R`, m), which
    no fit guesses."""
    spec = LAWS[name]
    missing = [k for k in spec.geometry if k not in geometry]
    unknown = sorted(set(geometry) - set(spec.geometry))
    if missing or unknown:
        raise ValueError(
            f"law {name!r} needs its {', '.join(missing)} (m), which no fit guesses: give it "
            f"(--param {missing[0]}=... on the command line), or pass a law object"
            if missing
            else f"starting_law({name!r}) takes no {', '.join(unknown)}: only the law's "
            f"geometry ({', '.join(spec.geometry) or 'none'})"
        )
    if spec.start is not None:
        return law(name, **spec.start(m=m, v0=v0, e=e, T=T, **geometry))
    T = 1e-3 if T is None or not np.isfinite(T) else T
    log_e = math.log(min(max(e, 1e-6), 0.999999))
    zeta = -log_e / math.sqrt(math.pi**2 + log_e**2)
    try:
        if spec.state is not None:  # Maxwell: a spring of period 2 T in series with a dashpot
            omega = math.pi / T
            return law(name, c=_in_range(m * omega**2), b=_in_range(m * omega / max(zeta, 1e-3)))
        n, p = exponents(spec)
        x_star = v0 * T / _undamped_tau(n)
        c = _in_range(m * v0**2 / x_star ** (n + 1.0))
        # 2 zeta sqrt(m c_linear), over x*^p
        damping = _in_range(2.0 * zeta * math.sqrt(m * m * v0**2 / x_star**2) / x_star**p)
    except (OverflowError, ZeroDivisionError):
        raise ValueError(
            f"T = {T:g} s at v0 = {v0:g} m/s and m = {m:g} kg asks for a stiffness outside "
            "float64's range: check the units (s, m/s, kg)"
        ) from None
    # with a dashpot and a dry force, each takes half the energy lost, not all of it (which
    # started Bingham-modified at e = 0.31 at the slowest of speeds measured at e = 0.9:
    # outside its table, so a first fit compiled the integration too)
    share = 0.5 if "P" in spec.parameters and {"b", "b1"} & set(spec.parameters) else 1.0
    if share < 1.0:  # the damping ratio of the e that loses `share` of the energy
        log_half = 0.5 * math.log(1.0 - share * max(1.0 - e**2, 1e-6))
        damping *= -log_half / math.sqrt(math.pi**2 + log_half**2) / max(zeta, 1e-12)
    params = {"c": c, "n": n, "p": p}
    for key in spec.parameters:
        if key in ("b", "b1"):
            params[key] = damping
        elif key == "a":
            params[key] = max(1.0 - e, 1e-3) / v0
        elif key == "d":  # Hunt-Crossley's d = 1.5 a (Drake's point contact)
            params[key] = 1.5 * max(1.0 - e, 1e-3) / v0
        elif key == "m_eff":  # the laws whose damping is set for a mass
            params[key] = m
        elif key == "P":
            energy = 0.5 * m * v0**2 * max(1.0 - e**2, 1e-3) * share
            params[key] = energy / (e * x_star) / (2.0 if _dry_both_ways(spec, v0) else 1.0)
        elif key == "e_nominal":
            params[key] = min(max(e, 0.05), 0.999)
        elif key == "w":  # DMT: a pull-off 2 pi w R of 1 % of the contact's force scale
            params[key] = 0.01 * m * v0**2 / x_star / (2.0 * math.pi * geometry["R"])
    params.update(geometry)
    return law(name, **{k: v for k, v in params.items() if k in spec.parameters})


def _in_range(value: float) -> float:
    """`value`, which must be a float64 number > 0 (an `OverflowError` otherwise)."""
    if not 0 < value < math.inf:
        raise OverflowError(value)
    return value


def _dry_both_ways(spec, v0) -> bool:
    """The dry force acts in restitution too (Bingham), so it dissipates about twice per
    contact what it does in compression alone (law 9)."""
    unit = {"c": 1.0, "b": 0.0, "b1": 0.0, "P": 1.0}
    return float(spec.coefficients(unit, v0)[5]) != 0.0


@dataclasses.dataclass
class Ranking:
    """One law's fit in a comparison: the `Fit`; `sum_sq`, the sum of its squared residuals
    (with sigmas the sum of squared normalised residuals, a chi-square; without them
    `e_fit - e` and `(T_fit - T)/T`, unweighted); the number of free parameters `k`; and
    AIC/BIC (with sigmas only, else `None`). `chi2` is the old name of `sum_sq`;
    `reduced_chi2`, `dof`, `p_value`, `rms_e` and `rms_T` are the fit's (`Fit`)."""

    name: str
    fit: Fit
    sum_sq: float
    k: int
    aic: float | None
    bic: float | None

    @property
    def chi2(self) -> float:
        """The old name of `sum_sq` (a chi-square only when sigmas were given)."""
        return self.sum_sq

    @property
    def dof(self) -> int:
        return int(self.fit.dof)

    @property
    def reduced_chi2(self) -> float:
        return float(self.fit.reduced_chi2)

    @property
    def p_value(self) -> float:
        return float(self.fit.p_value)

    @property
    def rms_e(self) -> float:
        return float(self.fit.rms_e)

    @property
    def rms_T(self) -> float:
        return float(self.fit.rms_T)

    def summary(self) -> str:
        """The law's place in the comparison (sum of squares, k, AIC, BIC), then its fit
        (`Fit.summary()`), every number with its unit."""
        if self.fit.weighted:
            what = "chi2: the sum of squared normalised residuals"
        else:
            what = (
                "sum of squared residuals e_fit - e and (T_fit - T)/T, unweighted (no "
                "sigmas: not a chi-square; .chi2 is the same number)"
            )
        rows = [("sum_sq", f"{format_value(self.sum_sq, '')} ({what})")]
        rows += [
            (k, format_value(getattr(self, k), None if k == "k" else ""))
            for k in ("k", "aic", "bic")
        ]
        return format_fields(f"Ranking of {self.name}", rows) + "\n" + self.fit.summary()

    def to_dict(self) -> dict:
        """`name`, `sum_sq` (also as `chi2`, its old name), `k`, `dof`, `reduced_chi2`,
        `p_value`, `rms_e`, `rms_T`, `aic`, `bic` and the `fit` (`Fit.to_dict()`), as
        plain numbers (NaN and missing as None)."""
        names = (
            "name",
            "sum_sq",
            "chi2",
            "k",
            "dof",
            "reduced_chi2",
            "p_value",
            "rms_e",
            "rms_T",
            "aic",
            "bic",
        )
        head = {k: jsonable(getattr(self, k)) for k in names}
        return {**head, "fit": self.fit.to_dict()}

    def __repr__(self) -> str:
        return self.summary()


class BadFitWarning(UserWarning):
    """The best law of `compare_laws` does not fit the data (see `fits_badly`)."""


# without sigmas, what "fits badly" means: RMS residuals above these (e: absolute, a
# restitution measured to +-0.01 is a good repeatability; T: relative, 5 %)
MAX_RMS_E = 0.01
MAX_RMS_T = 0.05
# with sigmas: a chi-square this improbable if the law were right
MIN_P_VALUE = 1e-3


def fits_badly(fit: Fit, *, max_rms_e=MAX_RMS_E, max_rms_T=MAX_RMS_T) -> str | None:
    """Why `fit` (one concrete `Fit`) fits its data badly, or `None`. With sigmas: a
    reduced chi-square well above 1, i.e. `p_value < 1e-3` (a chi-square that large has
    less than 0.1 % chance if the law were right and the sigmas the data's scatter).
    Without sigmas: the RMS of `e_fit - e` above `max_rms_e` (0.01) or that of
    `(T_fit - T)/T` above `max_rms_T` (5 %). A fit with no degree of freedom (as many
    data as free parameters) is never judged badly: it cannot be judged."""
    dof = int(fit.dof)
    if dof <= 0:
        return None
    if fit.weighted:
        p = float(fit.p_value)
        if p < MIN_P_VALUE:
            return (
                f"reduced chi-square {float(fit.reduced_chi2):.3g} with {dof} degrees of "
                f"freedom (p = {p:.2g} < {MIN_P_VALUE:g}: its residuals are far larger than "
                "the sigmas)"
            )
        return None
    reasons = []
    rms_e, rms_T = float(fit.rms_e), float(fit.rms_T)
    if np.isfinite(rms_e) and rms_e > max_rms_e:
        reasons.append(f"RMS of e_fit - e = {rms_e:.3g}")
    if np.isfinite(rms_T) and rms_T > max_rms_T:
        reasons.append(f"RMS of (T_fit - T)/T = {100 * rms_T:.3g} %")
    if not reasons:
        return None
    return (
        " and ".join(reasons) + f" (without sigmas, badly means an RMS residual above "
        f"{max_rms_e:g} in e or {100 * max_rms_T:g} % in T; give sigmas to judge against "
        "the data's own scatter)"
    )


@quietly_compiled
def compare_laws(
    *,
    m,
    v0,
    e,
    T=None,
    sigma_e=None,
    sigma_T=None,
    laws=PAPER_LAWS,
    separation="force",
    progress: bool | AbstractMeter = True,
    warn: bool = True,
    max_rms_e=MAX_RMS_E,
    max_rms_T=MAX_RMS_T,
    workers: int | None = None,
    callback=None,
    errors: str = "raise",
    **calibrate_options,
) -> list[Ranking]:
    """Fit every law of `laws` to the same measurements and rank them, best first.

    `laws`: names of the law table (started from `starting_law`), or law objects such as
    a user's `custom_law(...)`, each started from its own parameters.

    Ranked by AIC (`chi2 + 2k`, Gaussian errors) when sigmas are given, else by the sum of
    squared residuals (`e_fit - e` and `(T_fit - T)/T`). Laws with more free parameters
    than data are skipped.

    The best law is not thereby a good one: with `warn`, a `BadFitWarning` says when it
    fits badly, which means (`fits_badly`): with sigmas, a reduced chi-square well above
    1 (`p_value < 1e-3`); without sigmas, an RMS of `e_fit - e` above `max_rms_e` (0.01)
    or of `(T_fit - T)/T` above `max_rms_T` (0.05, i.e. 5 %). Each `Ranking` carries the
    numbers (`reduced_chi2`, `dof`, `rms_e`, `rms_T`).

    `progress`: a meter of the fits: `True` the default one (on stderr), `False` none, or
    an `AbstractMeter`. `workers`: how many fits run side by side (threads; a first call
    spends most of its time compiling, which XLA does outside Python's lock, so the laws
    compile in parallel): default one per CPU core, `1` one after another. The results do
    not depend on it.

    `callback(index, name, result)`, if given, is called on the calling thread after each
    law, as its fit ends (for progress): `index` its place in `laws`, `result` its
    `Ranking`, None for a law skipped, or the exception its fit raised. `errors`: `"raise"`
    (the default) stops at the first fit that raises; `"skip"` leaves that law out of the
    ranking and goes on (the callback sees its exception).

    **Example**: `compare_laws(m=0.0027, v0=[1, 2, 3], e=[0.9, 0.87, 0.85])[0].name`.
    """
    if errors not in ("raise", "skip"):
        raise ValueError(f"errors must be 'raise' or 'skip', got {errors!r}")
    v0_rows = np.atleast_1d(np.asarray(v0, dtype=float))
    e_rows = np.broadcast_to(np.atleast_1d(np.asarray(e, dtype=float)), v0_rows.shape)
    T_rows = None
    if T is not None:
        T_rows = np.broadcast_to(
            np.atleast_1d(
                np.asarray([np.nan if t is None else t for t in np.atleast_1d(T)], dtype=float)
            ),
            v0_rows.shape,
        )
    middle = int(np.argsort(v0_rows)[len(v0_rows) // 2])
    n_data = len(e_rows) + (0 if T_rows is None else int(np.sum(np.isfinite(T_rows))))
    has_sigma = sigma_e is not None or sigma_T is not None
    jobs, skipped = [], []  # (index, name, law or name, free), in the order of `laws`
    for index, entry in enumerate(laws):
        if isinstance(entry, AbstractLaw):  # a law object (a user's own): its own start
            name = entry.name
            free = _free_for_law(entry, has_T=T_rows is not None, n_data=n_data)
        else:
            name = entry
            free = _free_for(name, has_T=T_rows is not None, n_data=n_data)
        (skipped if len(free) > n_data else jobs).append((index, name, entry, free))
    # the main thread's precision, for the threads (JAX's config contexts are per thread)
    x64 = jnp.result_type(float) == jnp.float64

    def one(job):
        _, name, start, free = job
        if not isinstance(start, AbstractLaw):  # a name: the start from the middle row
            start = starting_law(
                name,
                m=float(m),
                v0=float(v0_rows[middle]),
                e=float(e_rows[middle]),
                T=None if T_rows is None else float(T_rows[middle]),
            )
        with jax.enable_x64(x64):
            fit = calibrate(
                start,
                m=m,
                v0=v0_rows,
                e=e_rows,
                T=T_rows,
                sigma_e=sigma_e,
                sigma_T=sigma_T,
                free=free,
                separation=separation,
                **calibrate_options,
            )
        sum_sq = float(jnp.sum(fit.residuals**2))
        k = len(free)
        aic = sum_sq + 2 * k if has_sigma else None
        bic = sum_sq + k * math.log(n_data) if has_sigma else None
        return Ranking(name, fit, sum_sq, k, aic, bic)

    workers = _workers(workers, len(jobs))
    rankings: list[Ranking | None] = [None] * len(jobs)
    with metered(progress, len(laws), "fitting laws") as bar:
        for index, name, _, _ in skipped:
            bar.update(1, f"{name} (skipped)")
            if callback is not None:
                callback(index, name, None)
        pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers)
        try:
            futures = {pool.submit(one, job): i for i, job in enumerate(jobs)}
            for future in concurrent.futures.as_completed(futures):
                index, name, _, _ = jobs[futures[future]]
                try:
                    result = rankings[futures[future]] = future.result()
                except Exception as error:
                    if errors == "raise":
                        raise
                    result = error
                bar.update(1, name)
                if callback is not None:
                    callback(index, name, result)
        finally:  # an interrupt or a failed fit: the fits not started are dropped
            pool.shutdown(wait=False, cancel_futures=True)
    key = (lambda r: r.aic) if has_sigma else (lambda r: r.sum_sq)
    rankings = sorted((r for r in rankings if r is not None), key=key)
    if warn and rankings:
        why = fits_badly(rankings[0].fit, max_rms_e=max_rms_e, max_rms_T=max_rms_T)
        if why is not None:
            warnings.warn(
                f"the best law, {rankings[0].name}, fits these data badly: {why}; no law of "
                f"{', '.join(r.name for r in rankings)} describes them; check the data and "
                "their sigmas, or try other laws",
                BadFitWarning,
                stacklevel=2,
            )
    return rankings


def _workers(workers, jobs: int) -> int:
    """How many fits run side by side: `workers` (an integer >= 1), default one per CPU
    core, never more than the fits."""
    if workers is None:
        workers = os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    return max(1, min(workers, jobs))


def _free_for_law(law, *, has_T, n_data):
    """A law object's free parameters: those a table law of its name frees, else (a
    user's law) every parameter, but the stiffness `c` when no T was measured and there
    is one more parameter than the data can fix."""
    if law.name in LAWS:
        return _free_for(law.name, has_T=has_T, n_data=n_data)
    names = tuple(law.parameters)
    if not has_T and "c" in names and len(names) > 1:
        names = tuple(k for k in names if k != "c")
    return names


def _free_for(name, *, has_T, n_data):
    # without T, a one-group law's e depends on beta alone: c and the damping never both
    stiffness = has_T or (n_data > 1 and not LAWS[name].one_group)
    free = default_free(LAWS[name], stiffness=stiffness)
    return default_free(LAWS[name], stiffness=stiffness, dry=n_data > len(free))
