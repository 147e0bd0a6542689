"""The model a bounce fit runs: `bounce`'s chain (closed-form flights, one impact solve per
contact) started at the first observed impact, its weighted residuals and their Jacobian in
one forward-mode pass (compiled once per law, data kind and size bucket), and the stages a
fit is made of (`BounceProblem`, `Stage`; `run_stage`, `tune_damping`, `rebase`)."""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._laws import AbstractLaw, damping_parameter
from .._least_squares import levenberg_marquardt
from .._solve.bounce import chain, trajectory_from_records
from .parameters import from_unbounded, law_with, to_unbounded


class ChainSpec(eqx.Module):
    """The static part of a fit: what is fitted and how the chain is solved."""

    kind: str = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    nuisance: tuple = eqx.field(static=True)
    has_drag: bool = eqx.field(static=True)
    y_sign: float = eqx.field(static=True)
    options: object = eqx.field(static=True)


def unpack(theta, law, data, spec):
    nf = len(spec.free)
    fitted = law_with(law, spec.free, theta[:nf])
    q = {name: theta[nf + i] for i, name in enumerate(spec.nuisance)}
    t1 = data["t1"] + q["t_impact"] * data["t_unit"]
    v1 = data["v1"] * jnp.exp(q["v_impact"])
    drag = None
    if spec.has_drag:
        drag = data["drag"] * jnp.exp(q.get("drag", 0.0))
    floor = data["floor"] + q.get("floor", 0.0) * data["y_unit"]
    scale = data["scale"] * jnp.exp(q.get("length_scale", 0.0))
    return fitted, t1, v1, drag, floor, scale


def chain_residuals(theta, law, m, g, data, spec):
    """Weighted residuals, and the chain's e, impact speeds, times and durations."""
    fitted, t1, v1, drag, floor, scale = unpack(theta, law, data, spec)
    ts = data["t"] if spec.kind == "trajectory" else None
    start = (t1, jnp.zeros_like(t1), -v1)
    records, flight0, carry = chain(
        fitted, m, g, drag, start, data["t_end"], data["min_flight"], ts, spec.options
    )
    if spec.kind == "impacts":
        predicted = records["t_land"][data["index"]]
        observed = data["times"]
    else:
        height = trajectory_from_records(records, flight0, carry, ts, m, g, drag)[0]
        height = jnp.where(jnp.isfinite(height), height, 0.0)
        predicted = floor + spec.y_sign * scale * height
        observed = data["y"]
    residuals = jnp.where(data["mask"], (predicted - observed) / data["sigma"], 0.0)
    aux = dict(
        predicted=predicted,
        t_land=records["t_land"],
        v_in=records["v_in"],
        T=records["T"],
        valid=records["valid"],
        status=records["status"],
    )
    return residuals, records["e"], aux


@eqx.filter_jit
def evaluate_chain(theta, law, m, g, data, spec):
    """`(r, e, aux)` and their Jacobians `dr/dtheta`, `de/dtheta`, in one forward pass."""

    def stacked(th):
        r, e, aux = chain_residuals(th, law, m, g, data, spec)
        return jnp.concatenate([r, e]), (r, e, aux)

    jacobian, (r, e, aux) = jax.jacfwd(stacked, has_aux=True)(theta)
    n = r.shape[0]
    return r, e, aux, jacobian[:n], jacobian[n:]


@dataclasses.dataclass(frozen=True)
class BounceProblem:
    """What a stage of a bounce fit works on: the `law` (its `free` parameters at their
    current values), the mass `m` (kg) and gravity `g` (m/s^2), the `kind` of data
    ("impacts" or "trajectory"), the sign of the data's y axis `y_sign` (+1 up, -1 down),
    the chain's `options` (a `BounceOptions`: the separation, the solver, `max_impacts`
    modelled impacts), the `nuisance` names and the `data` arrays (reference values of the
    nuisance included; see `chain_residuals`). `fit_bounces` starts one without data; its
    stages fill them in."""

    law: AbstractLaw
    free: tuple
    m: float
    g: float
    kind: str
    y_sign: float
    options: object
    nuisance: tuple = ()
    data: dict = dataclasses.field(default_factory=dict)

    def spec(self, free=None) -> ChainSpec:
        """The static part of the compiled model (`free`: default the problem's)."""
        return ChainSpec(
            kind=self.kind,
            free=self.free if free is None else free,
            nuisance=self.nuisance,
            has_drag="drag" in self.data,
            y_sign=self.y_sign,
            options=self.options,
        )

    @property
    def size(self) -> int:
        """The number of fitted parameters: the law's `free` ones, then the `nuisance`."""
        return len(self.free) + len(self.nuisance)

    def masked(self, mask, index=None) -> "BounceProblem":
        """The problem fitting the data where `mask` (bool, one per measurement) holds, the
        detections being impacts number `index` (impact times; capped at the last modelled
        impact), both padded to the data's size bucket."""
        n_pad = self.data["times" if self.kind == "impacts" else "t"].size
        data = dict(self.data)
        if index is not None:
            last = self.options.max_impacts - 1
            data["index"] = np.pad(np.minimum(index, last), (0, n_pad - index.size))
        data["mask"] = np.pad(mask, (0, n_pad - mask.size))
        return dataclasses.replace(self, data=data)


@dataclasses.dataclass(frozen=True)
class Stage:
    """One Levenberg-Marquardt fit of a `BounceProblem` (`run_stage`), and where it ended.

    The parameters `theta` are the law's `free` parameters, then the `nuisance`, in the
    coordinates the optimiser moves: a law parameter as `to_unbounded` of its SI value (its
    logarithm); the nuisance as offsets from the problem's reference values, `t_impact` in
    units of `data["t_unit"]` (s), `floor` in units of `data["y_unit"]` (y units),
    `v_impact`, `length_scale` and `drag` as the logarithm of their ratio to the reference.

    - `active`: bool per parameter, the ones this stage moved (the others were held).
    - `theta`: the optimum.
    - `residuals`: `(model - data) / sigma` there (dimensionless; 0 where masked or
      padded); `jacobian`: `d residuals / d theta`.
    - `e`: the restitution of each modelled impact there; `e_jacobian`: `d e / d theta`.
    - `chain`: the chain's arrays there: per modelled impact `t_land` (s), `v_in` (m/s),
      `T` (s), `valid`, `status`; per measurement `predicted` (s or y units).
    - `history`: the loss `|residuals|^2 / 2` at each accepted step of this stage.
    - `converged`: whether this stage met its tolerance.
    - `iterations`: the accepted steps of this stage and of every stage before it.
    """

    active: np.ndarray
    theta: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    e: np.ndarray
    e_jacobian: np.ndarray
    chain: dict
    history: np.ndarray
    converged: bool
    iterations: int


def run_stage(
    problem: BounceProblem, active, *, max_iter: int, tol: float, before: Stage | None = None
) -> Stage:
    """One Levenberg-Marquardt fit of `problem`'s `active` parameters through the compiled
    model, from zero nuisance offsets, with at most `max_iter` steps and tolerance `tol`;
    its `iterations` count on from the stage `before` it."""
    spec = problem.spec()
    data = {k: jnp.asarray(v) for k, v in problem.data.items()}
    m_, g_ = jnp.asarray(problem.m, float), jnp.asarray(problem.g, float)
    law = problem.law

    def evaluate(theta):
        r, e, aux, J, J_e = evaluate_chain(jnp.asarray(theta), law, m_, g_, data, spec)
        return (
            np.asarray(r),
            np.asarray(J),
            (np.asarray(e), np.asarray(J_e), jax.tree_util.tree_map(np.asarray, aux)),
        )

    theta0 = np.concatenate(
        [
            [float(to_unbounded(k, law.parameters[k])) for k in problem.free],
            np.zeros(len(problem.nuisance)),
        ]
    )
    active = np.asarray(active, dtype=bool)
    result = levenberg_marquardt(evaluate, theta0, active, max_iter=max_iter, tol=tol)
    e, e_jacobian, chain = result.extra
    return Stage(
        active=active,
        theta=result.theta,
        residuals=result.residuals,
        jacobian=result.jacobian,
        e=e,
        e_jacobian=e_jacobian,
        chain=chain,
        history=result.history,
        converged=result.converged,
        iterations=result.iterations + (0 if before is None else before.iterations),
    )


def tune_damping(problem: BounceProblem, e_target: float):
    """`problem`'s law with the damping set so that the first modelled impact has
    restitution `e_target` (a few secant steps on its logarithm, through the same compiled
    model); the law unchanged when no damping parameter is free."""
    law = problem.law
    damping = damping_name(law, problem.free)
    if damping is None:
        return law
    spec = problem.spec(free=(damping,))
    jdata = {k: jnp.asarray(v) for k, v in problem.data.items()}
    m, g = jnp.asarray(problem.m, float), jnp.asarray(problem.g, float)
    zeros = jnp.zeros(len(problem.nuisance))

    def first_e(log_value):
        theta = jnp.concatenate([jnp.asarray([log_value]), zeros])
        _, e, _, _, J_e = evaluate_chain(theta, law, m, g, jdata, spec)
        return float(e[0]), float(J_e[0, 0])

    x = float(to_unbounded(damping, law.parameters[damping]))
    for _ in range(30):
        e, slope = first_e(x)
        if abs(e - e_target) < 1e-4 or not np.isfinite(slope) or slope == 0:
            break
        step = np.clip((e_target - e) / slope, -2.0, 2.0)
        if e == 0.0:  # captured: far too much damping
            step = -2.0
        x += float(step)
    return law.replace(**{damping: float(from_unbounded(damping, x))})


def rebase(problem: BounceProblem, theta) -> BounceProblem:
    """`problem` with its data's reference values and its law moved to `theta` (so the
    next stage starts at zero nuisance offsets)."""
    data = dict(problem.data)
    nf = len(problem.free)
    q = dict(zip(problem.nuisance, theta[nf:], strict=True))
    data["t1"] = np.asarray(float(data["t1"]) + q["t_impact"] * float(data["t_unit"]))
    data["v1"] = np.asarray(float(data["v1"]) * math.exp(q["v_impact"]))
    if "floor" in q:
        data["floor"] = np.asarray(float(data["floor"]) + q["floor"] * float(data["y_unit"]))
    if "length_scale" in q:
        data["scale"] = np.asarray(float(data["scale"]) * math.exp(q["length_scale"]))
    if "drag" in q:
        data["drag"] = np.asarray(float(data["drag"]) * math.exp(q["drag"]))
    law = law_with(problem.law, problem.free, jnp.asarray(theta[:nf]))
    return dataclasses.replace(problem, law=law, data=data)


def first_stage(problem: BounceProblem):
    """What a first fit frees: the nuisance and the damping alone (a stiffness freed from the
    start can wander to a distant local minimum before the damping has settled)."""
    damping = damping_name(problem.law, problem.free)
    return np.asarray(
        [k == damping or damping is None for k in problem.free] + [True] * len(problem.nuisance)
    )


def damping_name(law, free):
    name = damping_parameter(law)
    return name if name in free else None


def with_impacts(options, n):
    return type(options)(impact=options.impact, max_impacts=int(n))


def round_up(n, multiple):
    return int(multiple * math.ceil(max(n, 1) / multiple))
