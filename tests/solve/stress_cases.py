"""The stress sweep: every law over the whole physical range, against exact references.

Shared by `tests/test_stress.py` (a fast subset, and the full sweep marked slow) and
`benchmarks/stress.py` (the full sweep in float64 and float32, with a report).

Each member of a sweep draws the stiffness c in [1e2, 1e13] (N/m^n), the mass m in
[1e-6, 1e3] kg and the impact speed v0 in [1e-4, 1e2] m/s log-uniformly (a scrambled Sobol
sequence, plus every corner of that box at both ends of the damping range), and the law's
dimensionless damping group(s) from nearly elastic (e about 0.999) to over-damped. The
dimensional parameters are built from those groups, so that the reference only depends on
them: every law of the family `F = c x^n + b x^p v + P` is, in its natural units
`x* = (m v0^2/c)^(1/(n+1))`, `t* = x*/v0`, the problem `X'' = -X^n - beta X^p X' - P~` with
`beta = b x*^(p+1)/(m v0)` and `P~ = P x*/(m v0^2)`; Maxwell depends on
`mu = sqrt(m c)/b` only, with `t* = sqrt(m/c)`. References (float64, independent of JAX):

- Kelvin-Voigt: the closed form (`closed_forms.kelvin_voigt`), both criteria;
- Maxwell, force criterion, under-damped: the closed form; otherwise scipy;
- Hunt-Crossley family: e from `closed_forms.hunt_crossley_restitution(1.5 a v0)` (the
  group `alpha = D v0`), T from scipy;
- every other law: scipy DOP853 (`tests/reference.py`) at rtol 1e-12 on the
  nondimensional problem (c = m = v0 = 1 with the member's groups): the one-group
  scaling law `e = e(beta)`, `T = t* tau(beta)` is what is tested.
"""

from __future__ import annotations

import math

import numpy as np

C_RANGE = (1e2, 1e13)
M_RANGE = (1e-6, 1e3)
V_RANGE = (1e-4, 1e2)

# law -> {group name: (low, high)}: log-uniform ranges of the dimensionless groups.
# beta-like groups run from e ~ 0.999 to beyond critical damping.
GROUPS = {
    "kelvin_voigt": {"beta": (6e-4, 20.0)},
    "kelvin_voigt_modified": {"beta": (1e-3, 100.0)},
    "bingham": {"beta": (6e-4, 20.0), "P": (1e-4, 3.0)},
    "bingham_modified": {"beta": (1e-3, 100.0), "P": (1e-4, 3.0)},
    "bingham_compression": {"P": (1e-4, 3.0)},
    "maxwell": {"mu": (6e-4, 30.0)},
    "hertz_viscous": {"beta": (1e-3, 30.0)},
    "hertz_modified": {"beta": (1e-3, 30.0)},
    "hertz_rate": {"beta": (1e-3, 30.0)},
    "hunt_crossley": {"alpha": (1.5e-3, 100.0), "n": (1.0, 2.5)},
}
NOMINAL_GROUPS = {"one_minus_e": (1e-3, 0.95)}  # e_nominal from 0.999 down to 0.05
LINEAR_GROUPS = ("n",)  # sampled uniformly, not log-uniformly

# (n, p, damping parameter, dry parameter) of the family laws
FAMILY = {
    "kelvin_voigt": (1.0, 0.0, "b", None),
    "kelvin_voigt_modified": (1.0, 1.0, "b1", None),
    "bingham": (1.0, 0.0, "b", "P"),
    "bingham_modified": (1.0, 1.0, "b1", "P"),
    "bingham_compression": (1.0, 0.0, None, "P"),
    "hertz_viscous": (1.5, 0.0, "b", None),
    "hertz_modified": (1.5, 1.0, "b", None),
    "hertz_rate": (1.5, 0.5, "b1", None),
}
STATUS = {"separated": 0, "stuck": 1, "captured": 2, "out_of_steps": 3, "failed": 5}


def groups_of(name):
    return GROUPS.get(name, NOMINAL_GROUPS)


def sample(name, n_sobol=64, seed=0, corners=True):
    """Members of the sweep: a dict of float64 numpy arrays `c, m, v0` and the groups."""
    from scipy.stats import qmc

    groups = groups_of(name)
    names = ["c", "m", "v0"] + list(groups)
    ranges = [C_RANGE, M_RANGE, V_RANGE] + [groups[g] for g in groups]
    unit = qmc.Sobol(len(names), scramble=True, seed=seed).random(n_sobol)
    if corners:
        box = np.array(np.meshgrid(*[[0.0, 1.0]] * 3, indexing="ij")).reshape(3, -1).T
        extra = []
        for row in box:
            for level in (0.0, 1.0):
                extra.append(list(row) + [level] * len(groups))
        unit = np.vstack([np.array(extra), unit])
    out = {}
    for k, key in enumerate(names):
        lo, hi = ranges[k]
        if key in LINEAR_GROUPS:
            out[key] = lo + (hi - lo) * unit[:, k]
        else:
            out[key] = np.exp(np.log(lo) + (np.log(hi) - np.log(lo)) * unit[:, k])
    return out


def nominal_alpha(name, e_nominal):
    """`alpha = D v0` of a Hunt-Crossley-family law set from a nominal restitution."""
    import jaximpact as ji

    spec = ji.LAWS[name]
    c, _, b, _, _, _ = spec.coefficients({"c": 1.0, "e_nominal": e_nominal, "n": 1.5}, 1.0)
    return np.asarray(b, dtype=float) / c


def parameters(name, members):
    """Dimensional law parameters (SI) and the time scale `t*` of every member."""
    c, m, v0 = members["c"], members["m"], members["v0"]
    if name == "maxwell":
        return {"c": c, "b": np.sqrt(m * c) / members["mu"]}, np.sqrt(m / c)
    if name == "hunt_crossley":
        n = members["n"]
        x_star = (m * v0**2 / c) ** (1.0 / (n + 1.0))
        return {"c": c, "a": members["alpha"] / (1.5 * v0), "n": n}, x_star / v0
    if name not in FAMILY:  # a law set from a nominal restitution
        x_star = (m * v0**2 / c) ** (1.0 / 2.5)
        e_nominal = 1.0 - members["one_minus_e"]
        return {"c": c, "e_nominal": e_nominal, "n": np.full_like(c, 1.5)}, x_star / v0
    n, p, damping, dry = FAMILY[name]
    x_star = (m * v0**2 / c) ** (1.0 / (n + 1.0))
    params = {"c": c}
    if damping is not None:
        params[damping] = members["beta"] * m * v0 / x_star ** (p + 1.0)
    if dry is not None:
        params[dry] = members["P"] * m * v0**2 / x_star
    return params, x_star / v0


def _nondimensional(name, members, k):
    """(reference law name, parameters) of member k at c = m = v0 = 1."""
    if name == "maxwell":
        return "maxwell", {"c": 1.0, "b": 1.0 / members["mu"][k]}
    if name == "hunt_crossley":
        return "hunt_crossley", {"c": 1.0, "a": members["alpha"][k] / 1.5, "n": members["n"][k]}
    if name not in FAMILY:
        alpha = float(nominal_alpha(name, 1.0 - members["one_minus_e"][k]))
        return "hunt_crossley", {"c": 1.0, "a": alpha / 1.5, "n": 1.5}
    n, p, damping, dry = FAMILY[name]
    params = {"c": 1.0}
    if damping is not None:
        params[damping] = float(members["beta"][k])
    if dry is not None:
        params[dry] = float(members["P"][k])
    return name, params


_CACHE: dict = {}


def _phi_over_square(u):
    """`(u - log(1 + u)) / u^2` in float64 numpy (a series near 0)."""
    if abs(u) < 1e-2:
        return sum((-u) ** k / (k + 2) for k in range(12))
    return (u - math.log1p(u)) / u**2


def hunt_crossley_restitution(alpha):
    """e of the Hunt-Crossley family at `alpha = D v0`, in float64 numpy/scipy whatever
    JAX's precision (the float32 sweep runs with x64 off): the root in (0, min(1, 1/alpha))
    of `e^2 phi(-alpha e) = phi(alpha)`, as `closed_forms.hunt_crossley_restitution`."""
    from scipy.optimize import brentq

    target = _phi_over_square(alpha)
    upper = min(1.0, (1.0 - 1e-15) / alpha)

    def residual(e):
        return e * e * _phi_over_square(-alpha * e) - target

    if residual(upper) <= 0.0:  # heavy damping: e is 1/alpha to machine precision
        return 1.0 / alpha
    return brentq(
        residual,
        0.0,
        upper,
        xtol=1e-17,
        rtol=8.9e-16,
        maxiter=400,
    )


def references(name, separation, members, rtol=1e-12):
    """Reference `e`, `tau = T/t*` and status (an int of `STATUS`) of every member."""
    from reference import reference_impact

    from jaximpact import closed_forms

    size = members["c"].shape[0]
    e = np.empty(size)
    tau = np.empty(size)
    status = np.empty(size, dtype=int)
    for k in range(size):
        ref_name, params = _nondimensional(name, members, k)
        hc = ref_name == "hunt_crossley"
        key = (ref_name, tuple(sorted(params.items())), "any" if hc else separation)
        if key not in _CACHE:
            if ref_name == "kelvin_voigt":
                cf = closed_forms.kelvin_voigt(1.0, params["b"], 1.0, 1.0, separation)
                out = dict(
                    e=float(cf["e"]),
                    T=float(cf["T"]) if int(cf["status"]) == 0 else math.inf,
                    status=["separated", "stuck", "captured"][int(cf["status"])],
                )
            elif ref_name == "maxwell" and separation == "force" and 0.5 * params["b"] ** -1 < 0.9:
                cf = closed_forms.maxwell(1.0, params["b"], 1.0, 1.0)
                out = dict(e=float(cf["e"]), T=float(cf["T"]), status="separated")
            else:
                out = reference_impact(
                    ref_name, params, m=1.0, v0=1.0, separation=separation, rtol=rtol
                )
                if hc:
                    out = dict(out, e=hunt_crossley_restitution(1.5 * params["a"]))
            _CACHE[key] = (out["e"], out["T"], STATUS[out["status"]])
        e[k], tau[k], status[k] = _CACHE[key]
    return e, tau, status


def sweep_function(
    name, separation, *, method="integrate", gradients=("jacfwd", "grad"), rtol=None
):
    """`f(params, m, v0)` -> dict of the impact's fields and the requested derivatives with
    respect to the law's parameters, vmapped over members and jitted (one compilation per
    law and criterion): `"jacfwd"`, the forward-mode Jacobian of (e, T); `"grad"`,
    `jax.grad` (reverse mode) of the scalar `e + T / stop_gradient(T)`, finite exactly when
    both reverse-mode gradients are (one reverse pass instead of two)."""
    import jax
    import jax.numpy as jnp

    import jaximpact as ji

    options = {} if rtol is None else {"rtol": rtol}

    def result(params, m, v0):
        return ji.impact(
            ji.law(name, **params), m=m, v0=v0, separation=separation, method=method, **options
        )

    def e_and_T(params, m, v0):
        r = result(params, m, v0)
        return jnp.stack([r.e, r.T])

    def scalar(params, m, v0):
        r = result(params, m, v0)
        return r.e + r.T / jax.lax.stop_gradient(r.T)

    def one(params, m, v0):
        r = result(params, m, v0)
        out = dict(
            e=r.e,
            T=r.T,
            x_max=r.x_max,
            t_max=r.t_max,
            F_max=r.F_max,
            dissipated=r.dissipated,
            status=r.status,
            steps=r.num_steps,
        )
        if "jacfwd" in gradients:
            out["jacfwd"] = jax.jacfwd(e_and_T)(params, m, v0)
        if "grad" in gradients:
            out["grad"] = jax.grad(scalar)(params, m, v0)
        return out

    return jax.jit(jax.vmap(one))


def run_sweep(
    name,
    separation,
    members,
    *,
    method="integrate",
    gradients=("jacfwd", "grad"),
    rtol=None,
    dtype=None,
):
    """Evaluate the sweep; returns (outputs as numpy, seconds for the first call, with
    tracing and compilation, and seconds for a second call)."""
    import time

    import jax
    import jax.numpy as jnp

    dtype = dtype or jnp.result_type(float)
    params, _ = parameters(name, members)
    fn = sweep_function(name, separation, method=method, gradients=gradients, rtol=rtol)
    args = (
        {k: jnp.asarray(v, dtype=dtype) for k, v in params.items()},
        jnp.asarray(members["m"], dtype=dtype),
        jnp.asarray(members["v0"], dtype=dtype),
    )
    start = time.perf_counter()
    out = jax.block_until_ready(fn(*args))
    first = time.perf_counter() - start
    start = time.perf_counter()
    jax.block_until_ready(fn(*args))
    again = time.perf_counter() - start
    return jax.tree_util.tree_map(np.asarray, out), first, again


def finite_rows(tree):
    """Boolean per member: every float leaf of `tree` finite."""
    import jax

    leaves = [np.asarray(x) for x in jax.tree_util.tree_leaves(tree)]
    ok = None
    for leaf in leaves:
        if leaf.dtype.kind != "f":
            continue
        row = np.all(np.isfinite(leaf.reshape(leaf.shape[0], -1)), axis=1)
        ok = row if ok is None else ok & row
    return ok


def summarise(name, separation, members, out, refs):
    """Counts and errors of one sweep (plain Python numbers, for JSON)."""
    e_ref, tau_ref, status_ref = refs
    _, t_star = parameters(name, members)
    status = out["status"]
    values = {k: out[k] for k in ("e", "T", "x_max", "t_max", "F_max", "dissipated") if k in out}
    # a failed member (out of steps, failed) has NaN in every field by the failure rule:
    # counted by its status, and its fields checked to be NaN, not numbers
    failed = (status == STATUS["out_of_steps"]) | (status == STATUS["failed"])
    failed_with_numbers = int(np.sum(failed & np.isfinite(np.asarray(out["e"]))))
    finite_values = finite_rows(values) | failed
    finite_fwd = finite_rows(out["jacfwd"]) | failed if "jacfwd" in out else None
    finite_rev = finite_rows(out["grad"]) | failed if "grad" in out else None
    both = (status == 0) & (status_ref == 0)
    e_err = np.abs(out["e"] - e_ref)[both]
    with np.errstate(invalid="ignore"):  # tau_ref is inf where the reference is captured
        T_err = (np.abs(out["T"] - tau_ref * t_star) / (tau_ref * t_star))[both]
    counts = {s: int(np.sum(status == v)) for s, v in STATUS.items()}
    mismatch = np.nonzero(status != status_ref)[0]
    summary = dict(
        law=name,
        separation=separation,
        members=int(status.shape[0]),
        counts=counts,
        ref_counts={s: int(np.sum(status_ref == v)) for s, v in STATUS.items()},
        status_mismatch=int(mismatch.size),
        mismatch_examples=[
            dict(
                member=int(k),
                got=int(status[k]),
                ref=int(status_ref[k]),
                e=float(out["e"][k]),
                e_ref=float(e_ref[k]),
                groups={g: float(members[g][k]) for g in members},
            )
            for k in mismatch[:5]
        ],
        nan_values=int(np.sum(~finite_values)) + failed_with_numbers,
        nan_jacfwd=None if finite_fwd is None else int(np.sum(~finite_fwd)),
        nan_grad=None if finite_rev is None else int(np.sum(~finite_rev)),
        nan_members=[
            dict(member=int(k), groups={g: float(members[g][k]) for g in members})
            for k in np.nonzero(
                ~finite_values
                | (False if finite_fwd is None else ~finite_fwd)
                | (False if finite_rev is None else ~finite_rev)
            )[0][:10]
        ],
        e_err_max=float(np.max(e_err)) if e_err.size else None,
        e_err_p99=float(np.percentile(e_err, 99)) if e_err.size else None,
        e_err_median=float(np.median(e_err)) if e_err.size else None,
        T_err_max=float(np.max(T_err)) if T_err.size else None,
        T_err_p99=float(np.percentile(T_err, 99)) if T_err.size else None,
        e_range=[float(np.min(e_ref)), float(np.max(e_ref))],
        steps_max=int(np.max(out["steps"])),
        steps_median=float(np.median(out["steps"])),
    )
    if "jacfwd" in out and "grad" in out:
        # forward and reverse mode must agree: grad of e + T/T is de + dT/T; compared as
        # log-sensitivities p d/dp, which have the same scale for every parameter
        params, _ = parameters(name, members)
        keys = list(out["jacfwd"])
        fwd = np.stack(
            [
                params[k] * (out["jacfwd"][k][:, 0] + out["jacfwd"][k][:, 1] / out["T"])
                for k in keys
            ],
            1,
        )
        rev = np.stack([params[k] * out["grad"][k] for k in keys], 1)
        ok = np.all(np.isfinite(fwd) & np.isfinite(rev), axis=1)
        scale = np.maximum(np.abs(fwd), np.abs(rev)).max(axis=1, keepdims=True)
        scale = np.where(scale > 0, scale, 1.0)
        diff = (np.abs(fwd - rev) / scale).max(axis=1)
        sep = ok & (status == 0)
        summary["fwd_rev_max_separated"] = float(np.max(diff[sep])) if np.any(sep) else None
        summary["fwd_rev_max_all"] = float(np.max(diff[ok])) if np.any(ok) else None
        summary["fwd_rev_disagree"] = int(np.sum(diff[ok] > 1e-5))
    if e_err.size:
        worst = np.nonzero(both)[0][np.argmax(e_err)]
        summary["worst_e_member"] = dict(
            member=int(worst), groups={g: float(members[g][worst]) for g in members}
        )
    return summary
