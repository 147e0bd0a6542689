"""`BounceFit`, the result of `fit_bounces`, and the statistics it reports: standard errors
from the Jacobian at the optimum, undetermined parameters, outliers."""

import dataclasses
import math

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from .._format import format_number, jsonable
from .._laws import AbstractLaw
from .._solve.bounce import BounceResult, bounce_options, solve_bounce
from .._solve.options import SolveOptions
from .bounce_model import BounceProblem, Stage, round_up
from .calibrate import law_units
from .parameters import law_with


class BounceFit(eqx.Module):
    """A law fitted to a bouncing ball, and how well it reproduces the measurements.

    Like `jaximpact.Fit`: `law`, `params` (SI), `stderr` (standard errors of the fitted
    parameters, law and nuisance, by name; `inf` for an undetermined one), `free` (the law
    parameters fitted), `residuals` (`(model - data) / sigma` for the data used, with the
    reported `sigma`),
    `loss` (half their sum of squares), `converged`, `iterations`, `history` (loss per
    accepted step of the last fit; `iterations` counts the steps of every stage). And:

    - `undetermined`: parameters the data cannot fix (see the module docstring); their
      values are the ones given, not estimates.
    - `nuisance`: `t_impact` (s, first impact), `v_impact` (m/s, its speed), `drop_height`
      (m, `v_impact^2 / 2g`, or its drag equivalent), `release_time` (s, when the ball was at
      that apex), and for a trajectory `floor` (y units) and `length_scale` (y units per
      metre); `drag` (1/m) when it was given or fitted.
    - `e`, `e_stderr`, `impact_speeds` (m/s), `impact_times` (s), `T` (s): the fitted
      chain, one entry per modelled impact (`num_impacts` of them).
    - `sigma`: the measurement noise used (s or y units), given or estimated from the
      residuals (then `stderr` includes that estimate, and with few data the errors
      `(estimate - truth) / stderr` follow Student's t with `dof` degrees of freedom rather
      than a normal law); `dof`: data minus parameters.
    - impact times: `times`, `index` (impact number of each used detection), `dropped`
      (positions in the input of detections not used: double, inconsistent, or
      outliers of the first fit), `missed` (impact numbers with no detection).
    - trajectory: `t`, `y`, `y_fit` (the data used and the model there), `dropped` (sample
      positions not used: before the release, or outliers).
    """

    kind: str = eqx.field(static=True)
    law: AbstractLaw
    params: dict
    stderr: dict
    free: tuple = eqx.field(static=True)
    undetermined: tuple = eqx.field(static=True)
    nuisance: dict
    e: np.ndarray
    e_stderr: np.ndarray
    impact_speeds: np.ndarray
    impact_times: np.ndarray
    T: np.ndarray
    num_impacts: int = eqx.field(static=True)
    residuals: np.ndarray
    loss: float = eqx.field(static=True)
    sigma: float = eqx.field(static=True)
    dof: int = eqx.field(static=True)
    converged: bool = eqx.field(static=True)
    iterations: int = eqx.field(static=True)
    history: np.ndarray
    times: np.ndarray | None = None
    index: np.ndarray | None = None
    missed: np.ndarray | None = None
    t: np.ndarray | None = None
    y: np.ndarray | None = None
    y_fit: np.ndarray | None = None
    dropped: np.ndarray | None = None
    m: float = eqx.field(static=True, default=1.0)
    g: float = eqx.field(static=True, default=9.81)
    separation: str = eqx.field(static=True, default="force")
    y_sign: float = eqx.field(static=True, default=1.0)

    def summary(self, units: str | None = None, title: str | None = None) -> str:
        """The fit as text: each parameter with its unit and standard error (or `held`,
        or `undetermined`), the first impact, what was used and dropped, and `e` per
        impact with its standard error. `units`: the data's (`s` for impact times, the
        trajectory's own, `y units` if not given); `title`: the first words (the
        law's name)."""
        units = units or ("s" if self.kind == "impacts" else "y units")
        converged = "converged" if self.converged else "NOT converged"
        lines = [
            f"{title or self.law.name}: {self.kind}, {converged} after {self.iterations} "
            f"iterations, noise {format_number(self.sigma, 3)} {units}"
        ]
        law_unit = law_units(self.law)
        for key, value in self.params.items():
            unit = law_unit.get(key, "")
            shown = format_number(value) + (f" {unit}" if unit else "")
            if key in self.undetermined:
                shown += "  (undetermined by these data: held, not estimated)"
            elif key in self.free:
                shown += f" ± {format_number(self.stderr[key], 2)}"
            else:
                shown += "  (held)"
            lines.append(f"  {key:<12} = {shown}")
        q = self.nuisance
        lines.append(
            f"  first impact at {q['t_impact']:.4f} s, {q['v_impact']:.4f} m/s "
            f"(drop height {q['drop_height']:.4f} m)"
        )
        if "floor" in q:
            lines.append(
                f"  floor {format_number(q['floor'])}, scale "
                f"{format_number(q['length_scale'])} {units}/m"
            )
        if "drag" in q:
            lines.append(f"  drag {format_number(q['drag'])} 1/m")
        if self.kind == "impacts":
            lines.append(
                f"  used {np.size(self.times)} detections; dropped "
                f"{list(map(int, self.dropped))}, missed impacts "
                f"{list(map(int, self.missed))}"
            )
        else:
            lines.append(f"  used {np.size(self.t)} samples; dropped {np.size(self.dropped)}")
        lines.append("  impact  speed (m/s)  e")
        for k in range(min(self.num_impacts, 12)):
            lines.append(
                f"  {k:>6}  {self.impact_speeds[k]:11.4f}  {self.e[k]:.4f} ± {self.e_stderr[k]:.4f}"
            )
        if self.num_impacts > 12:
            lines.append(f"  ... {self.num_impacts - 12} more")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The fit as plain numbers and lists (SI units; `sigma` and a trajectory's
        `floor` in the data's units), NaN as None: `kind`, `law` (its name), `params`,
        `stderr`, `free`, `undetermined`, `nuisance`, per modelled impact `e`, `e_stderr`,
        `impact_speeds`, `impact_times`, `T`, and `sigma`, `dof`, `loss`, `converged`,
        `iterations`, `dropped`, `used` (detections or samples), `missed` (impact fits)."""
        data = dict(
            kind=self.kind,
            law=self.law.name,
            params=self.params,
            stderr=self.stderr,
            free=list(self.free),
            undetermined=list(self.undetermined),
            nuisance=self.nuisance,
            e=self.e,
            e_stderr=self.e_stderr,
            impact_speeds=self.impact_speeds,
            impact_times=self.impact_times,
            T=self.T,
            sigma=self.sigma,
            dof=self.dof,
            loss=self.loss,
            converged=self.converged,
            iterations=self.iterations,
            dropped=self.dropped,
        )
        if self.kind == "impacts":
            data.update(missed=self.missed, used=int(np.size(self.times)))
        else:
            data.update(used=int(np.size(self.t)))
        return jsonable(data)

    def __repr__(self) -> str:
        return self.summary()

    def bounce(self, t_end=None, max_impacts: int | None = None) -> BounceResult:
        """The fitted drop as a `BounceResult`, from the first modelled impact on (its
        `height(ts)` gives the fitted motion at any times, in metres)."""
        drag = self.nuisance.get("drag")
        options = bounce_options(
            self.law,
            SolveOptions(),
            separation=self.separation,
            max_impacts=max_impacts or round_up(self.num_impacts + 1, 16),
        )
        t1, v1 = self.nuisance["t_impact"], self.nuisance["v_impact"]
        if t_end is None:  # just past the last modelled impact
            times = self.impact_times[: self.num_impacts]
            t_end = float(times[-1]) + (
                0.5 * float(times[-1] - times[-2]) if times.size > 1 else 1e-3
            )
            if self.t is not None:
                t_end = max(t_end, float(np.max(self.t)))
        return solve_bounce(
            self.law,
            jnp.asarray(self.m, float),
            jnp.asarray(self.g, float),
            None if drag is None else jnp.asarray(drag, float),
            (jnp.asarray(t1, float), jnp.zeros(()), -jnp.asarray(v1, float)),
            jnp.asarray(t_end, float),
            jnp.asarray(0.0, float),
            options,
        )

    def predict(self, ts) -> np.ndarray:
        """The fitted trajectory at times `ts` (s), in the data's units (trajectory fits)."""
        if self.kind != "trajectory":
            raise ValueError("predict is for trajectory fits; an impact-time fit has impact_times")
        ts = np.asarray(ts, dtype=float)
        height = np.asarray(self.bounce(t_end=float(np.max(ts))).height(ts))
        height = np.where(np.isfinite(height), height, 0.0)
        return self.nuisance["floor"] + self.y_sign * self.nuisance["length_scale"] * height


@dataclasses.dataclass(frozen=True)
class Measurements:
    """The measurements of a finished fit, as `BounceFit` reports them.

    - `used`: bool per measurement (the detections in input order, or the trajectory's
      samples from the release on), True for those the last stage fitted.
    - `sigma_given`: whether the noise was given (`sigma=`), or is estimated from the
      residuals.
    - `fields`: `BounceFit`'s fields about the data: for impact times `times` (s), `index`,
      `missed`, `dropped`; for a trajectory `t` (s), `y`, `y_fit` (y units), `dropped`.
    """

    used: np.ndarray
    sigma_given: bool
    fields: dict


def statistics(problem: BounceProblem, stage: Stage, measured: Measurements):
    """Covariance from the Jacobian at `stage`'s optimum: the degrees of freedom, the
    variance factor, the parameters' standard errors (in `theta`'s coordinates),
    the undetermined parameters, and the standard error of each modelled impact's e."""
    p = stage.theta.size
    r, J = stage.residuals[: measured.used.size], stage.jacobian
    dof = max(int(measured.used.sum()) - p, 1)
    s2 = 1.0 if measured.sigma_given else float(r @ r) / dof
    U, S, Vt = np.linalg.svd(J, full_matrices=False)
    cutoff = S.max(initial=0.0) * 1e-8
    good = S > cutoff
    inv = np.where(good, 1.0 / np.where(good, S, 1.0) ** 2, 0.0)
    cov = s2 * (Vt.T * inv) @ Vt
    null = Vt[~good]
    se_theta = np.sqrt(np.maximum(np.diag(cov), 0.0))
    log_params = [True] * len(problem.free) + [name in _LOG_NUISANCE for name in problem.nuisance]
    undetermined = []
    for i, name in enumerate(problem.free + problem.nuisance):
        in_null = null.size and np.max(np.abs(null[:, i])) > 1e-3
        if in_null or (log_params[i] and se_theta[i] > 1.0):
            undetermined.append(name)
            se_theta[i] = np.inf
    J_e = stage.e_jacobian
    cov_e = np.einsum("ki,ij,kj->k", J_e, cov, J_e)
    return dof, s2, se_theta, undetermined, np.sqrt(np.maximum(cov_e, 0.0))


_LOG_NUISANCE = ("v_impact", "length_scale", "drag")  # fitted as logarithms


def _nuisance(problem: BounceProblem, theta, se_theta):
    """The nuisance parameters at `theta` in their units (see `BounceFit`), and their
    standard errors from `se_theta` (`theta`'s coordinates)."""
    data = {k: float(v) for k, v in problem.data.items() if np.ndim(v) == 0}
    nf, g = len(problem.free), problem.g
    q = dict(zip(problem.nuisance, theta[nf:], strict=True))
    se_q = dict(zip(problem.nuisance, se_theta[nf:], strict=True))
    t1 = float(data["t1"] + q["t_impact"] * data["t_unit"])
    v1 = float(data["v1"] * math.exp(q["v_impact"]))
    nuisance = {"t_impact": t1, "v_impact": v1}
    stderr = {}
    stderr["t_impact"] = float(se_q["t_impact"] * data["t_unit"])
    stderr["v_impact"] = float(v1 * se_q["v_impact"])
    drag = None
    if "drag" in data:
        drag = float(data["drag"] * math.exp(q.get("drag", 0.0)))
        nuisance["drag"] = drag
        stderr["drag"] = float(drag * se_q["drag"]) if "drag" in se_q else 0.0
    # the apex the first impact fell from
    if drag is None:
        height, fall = v1**2 / (2 * g), v1 / g
    else:
        v_t = math.sqrt(g / drag)
        w = min(v1 / v_t, 1 - 1e-15)
        height, fall = -(v_t**2) / (2 * g) * math.log1p(-(w**2)), v_t / g * math.atanh(w)
    nuisance["drop_height"] = height
    nuisance["release_time"] = t1 - fall
    stderr["drop_height"] = float(2 * height * se_q["v_impact"])
    if problem.kind == "trajectory":
        nuisance["floor"] = float(data["floor"] + q["floor"] * data["y_unit"])
        stderr["floor"] = float(se_q["floor"] * data["y_unit"])
        scale = float(data["scale"] * math.exp(q.get("length_scale", 0.0)))
        nuisance["length_scale"] = scale
        stderr["length_scale"] = (
            float(scale * se_q["length_scale"]) if "length_scale" in se_q else 0.0
        )
    return nuisance, stderr


def finish(problem: BounceProblem, stage: Stage, measured: Measurements) -> BounceFit:
    """The `BounceFit` of a finished fit: statistics at the optimum of its last `stage`
    (law parameters `problem.free`, then `problem.nuisance`), the fitted chain's e and
    impacts, and the `measured` data."""
    free, theta = problem.free, stage.theta
    nf = len(free)
    fitted_law = law_with(problem.law, free, jnp.asarray(theta[:nf]))
    dof, s2, se_theta, undetermined, e_se = statistics(problem, stage, measured)
    params = {k: float(v) for k, v in fitted_law.parameters.items()}
    stderr = {}
    for i, name in enumerate(free):
        stderr[name] = float(params[name] * se_theta[i]) if np.isfinite(se_theta[i]) else math.inf
    nuisance, nuisance_stderr = _nuisance(problem, theta, se_theta)
    stderr.update(nuisance_stderr)
    aux, fields = stage.chain, measured.fields
    valid = aux["valid"]
    count = int(np.sum(valid))
    if problem.kind == "impacts":  # the impacts the detections cover
        count = min(count, int(np.max(fields["index"])) + 1)
    else:
        count = min(count, int(np.sum(aux["t_land"][:count] <= np.max(fields["t"]))))
    sigma = float(float(problem.data["sigma"]) * math.sqrt(s2))
    r = stage.residuals[: measured.used.size]
    return BounceFit(
        kind=problem.kind,
        law=fitted_law,
        params=params,
        stderr=stderr,
        free=tuple(free),
        undetermined=tuple(undetermined),
        nuisance=nuisance,
        e=np.where(valid, stage.e, np.nan)[:count],
        e_stderr=np.where(valid, e_se, np.nan)[:count],
        impact_speeds=aux["v_in"][:count],
        impact_times=aux["t_land"][:count],
        T=aux["T"][:count],
        num_impacts=count,
        residuals=r[measured.used] / math.sqrt(s2),
        loss=float(0.5 * r @ r),
        sigma=sigma,
        dof=int(dof),
        converged=bool(stage.converged),
        iterations=int(stage.iterations),
        history=stage.history,
        m=problem.m,
        g=problem.g,
        separation=problem.options.impact.separation,
        y_sign=problem.y_sign,
        **fields,
    )


def find_outliers(r, used, threshold, sigma_given):
    """Data more than `threshold` robust standard deviations (1.4826 times the median
    absolute deviation; with a given noise, at least the given one) off the fit, at most a
    fifth of them, the worst first."""
    values = r[used]
    spread = 1.4826 * np.median(np.abs(values - np.median(values)))
    if sigma_given:
        spread = max(spread, 1.0)  # residuals are in units of the given noise
    bad = used & (np.abs(r) > threshold * max(spread, 1e-12))
    limit = max(1, int(used.sum()) // 5)
    if bad.sum() > limit:
        worst = np.argsort(-np.abs(np.where(bad, r, 0.0)))[:limit]
        bad = np.zeros_like(bad)
        bad[worst] = True
    return bad
