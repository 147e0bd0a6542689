"""The one least-squares driver of the fits (`fit_bounces`, `drop_design`): Levenberg-
Marquardt in numpy around a compiled `evaluate(theta) -> (residuals, Jacobian, extra)`.

numpy drives it, not optimistix, because each fit needs what optimistix's least-squares
solvers do not give: a mask of components held fixed between stages, a model that may fail at
a trial point (a NaN residual is a rejected step, not an error), and the `extra` outputs of the
accepted point. An eager `calibrate` runs it too (`optimizer="auto"`); a traced one keeps
optimistix's or optax's inside its program, and `fit_oblique` runs optimistix's
Levenberg-Marquardt around a host callback (its loss has kinks where impacts change between
sticking and slipping, and this driver stopped short on one).
"""

import dataclasses
import math

import numpy as np


@dataclasses.dataclass(frozen=True)
class LeastSquares:
    """A least-squares fit: the parameters `theta`, the `residuals` and `jacobian` there,
    the model's `extra` outputs there, the loss `|r|^2/2` at each accepted iterate
    (`history`), whether it `converged`, and the number of `iterations`."""

    theta: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    extra: object
    history: np.ndarray
    converged: bool
    iterations: int


def levenberg_marquardt(
    evaluate, theta0, active=None, *, max_iter: int, tol: float, max_step: float = np.inf
) -> LeastSquares:
    """Minimise `|r|^2/2` over the `active` components of `theta` (numpy driver around the
    compiled `evaluate(theta) -> (r, J, extra)`). Marquardt's scaling with a floor, so a
    direction the data do not see stays where it is. `active`: a mask of the components
    to move (default all). `max_step`: the largest move of one component in one step (a
    step beyond it is shortened along its direction), for parameters in logarithms or
    logits, where a long step can land where the loss is flat. Converged: the scaled
    gradient, the relative decrease or the step fell below `tol`, or no step lowers the
    loss any more."""
    theta = np.array(theta0, dtype=float)
    r, J, extra = evaluate(theta)
    cost = 0.5 * float(r @ r)
    history = [cost]
    lam, converged = 1e-3, False
    active = np.ones(theta.shape, bool) if active is None else np.asarray(active, dtype=bool)
    for _ in range(max_iter):
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
            break  # the model failed here (e.g. a contact solve ran out of steps)
        Ja = J[:, active]
        A = Ja.T @ Ja
        grad = Ja.T @ r
        diag = np.diag(A).copy()
        diag = np.maximum(diag, 1e-9 * max(diag.max(initial=0.0), 1e-300))
        if np.max(np.abs(grad) / np.sqrt(diag)) <= tol * max(math.sqrt(2 * cost), 1e-300):
            converged = True
            break
        improved = False
        while lam < 1e12:
            step = np.linalg.lstsq(A + lam * np.diag(diag), -grad, rcond=None)[0]
            step *= min(1.0, max_step / max(np.max(np.abs(step), initial=0.0), 1e-300))
            trial = theta.copy()
            trial[active] += step
            r_new, J_new, extra_new = evaluate(trial)
            cost_new = 0.5 * float(r_new @ r_new) if np.all(np.isfinite(r_new)) else np.inf
            if cost_new < cost:
                improved = True
                break
            lam *= 10.0
        if not improved:
            converged = True  # no direction lowers the loss: a minimum to working precision
            break
        reduction = (cost - cost_new) / max(cost, 1e-300)
        theta, r, J, extra, cost = trial, r_new, J_new, extra_new, cost_new
        history.append(cost)
        lam = max(lam / 10.0, 1e-12)
        if reduction < tol or np.max(np.abs(step)) < tol:
            converged = True
            break
    return LeastSquares(theta, r, J, extra, np.asarray(history), converged, len(history) - 1)
