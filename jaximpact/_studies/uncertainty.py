"""`propagate_uncertainty`: the spread of `e` and `T` from scattered parameters, to first
order (`J Sigma J^T`) and by Monte Carlo over the same law (vmapped), with the Monte Carlo
sampling error that says whether the two agree.
"""

import equinox as eqx
import numpy as np

from .._batch import prepare_rows
from .._format import PrintedFields
from .._progress import AbstractMeter
from .._status import Status
from .sensitivity import jacobian_batch


class Uncertainty(PrintedFields, eqx.Module):
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

    _TITLE = "Uncertainty of (e, T in s)"
    _SHOWN = (
        ("names", None),
        ("sigma", ""),
        ("nominal", ""),
        ("std_linear", ""),
        ("std_mc", ""),
        ("std_mc_error", ""),
        ("z_std", ""),
        ("n_samples", None),
        ("separated_fraction", ""),
    )

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
    progress: bool | AbstractMeter = False,
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
    skeleton, params, kinematics, _ = prepare_rows(law, None, m=m, v0=v0)
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
