"""`Posterior`: the draws of a calibration's parameters and what they imply."""

import math

import equinox as eqx
import numpy as np

from .._format import format_fields, format_value, jsonable
from .._xla_log import quietly_compiled
from .bands import Bands, prediction_bands
from .likelihood import Model
from .oblique_model import ObliqueBands, ObliqueModel, oblique_bands


class Posterior(eqx.Module):
    """The posterior of a fit's free parameters (and of its sampled noise scales).

    - `samples`: `{name: draws}` in SI units, shape `(chains * num_samples,)`; the law's
      free parameters (`free`; an oblique fit's: the tangential law's) and, where no sigma
      was given, the noise scales: `sigma_e` and `sigma_T` (s) of a calibration, `sigma`
      of a bounce fit, `sigma_e_t` and `sigma_omega` (rad/s) of an oblique fit.
    - `median`, `interval(0.9)` (the 5 and 95 % quantiles), `mean`, `std`.
    - `map`: the mode (maximum a posteriori) the Laplace approximation is centred on.
    - `diagnostics`: `r_hat` (worst over the parameters; NaN with one chain or for
      Laplace), `ess` (worst bulk effective sample size), `divergences` (count), with the
      per-parameter values; see `posterior`.
    - `log_evidence`: log marginal likelihood of the data (nats), from the Laplace
      approximation at the mode for both methods (NaN where the mode's Hessian is not
      negative definite).
    - `method`: "nuts" or "laplace"; `priors`: `{name: (kind, a, b)}`; `noise`, `nu`;
      `law_name`, `units`; `z`: the draws in the sampler's unbounded coordinates.
    - `law_parameters`: every parameter of the fitted law (SI; the fixed ones as fitted
      with), so that `law_at` builds the law at any draw.
    - `predict(v0=...)`: bands of e and T at new speeds (of an oblique fit's posterior,
      `predict(angle=...)`: bands of e_t, the spin and the rebound angle at incidence
      angles); `plot(path)`; `summary()`; `to_dict()` and `Posterior.from_dict` (without
      the forward model).
    - `law_at(values)`, `median_law`, `draw_laws(n)`: the law at given values of the free
      parameters, at the medians, at `n` evenly thinned draws (what `export(post, ...)`
      exports, and over which it gives the engine's band).
    """

    samples: dict
    z: np.ndarray
    names: tuple = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    method: str = eqx.field(static=True)
    law_name: str = eqx.field(static=True)
    noise: str = eqx.field(static=True)
    nu: float = eqx.field(static=True)
    units: dict
    priors: dict
    map: dict
    log_evidence: float
    diagnostics: dict
    model: Model | None = None
    law_parameters: dict | None = None

    # ------------------------------------------------------------------ statistics

    @property
    def median(self) -> dict:
        """`{name: median}` (SI)."""
        return {k: float(np.median(v)) for k, v in self.samples.items()}

    @property
    def mean(self) -> dict:
        return {k: float(np.mean(v)) for k, v in self.samples.items()}

    @property
    def std(self) -> dict:
        return {k: float(np.std(v)) for k, v in self.samples.items()}

    def interval(self, level: float = 0.9) -> dict:
        """`{name: (lo, hi)}`: the `(1 - level)/2` and `(1 + level)/2` quantiles of the
        draws (for 0.9, the 5 and 95 % quantiles)."""
        if not 0 < level < 1:
            raise ValueError(f"level must lie in (0, 1), e.g. 0.9, got {level!r}")
        lo, hi = (1 - level) / 2, (1 + level) / 2
        return {
            k: (float(np.quantile(v, lo)), float(np.quantile(v, hi)))
            for k, v in self.samples.items()
        }

    @property
    def num_draws(self) -> int:
        return int(self.z.shape[0])

    # ------------------------------------------------------------------ laws

    def law_at(self, values: dict | None = None):
        """The fitted law with its free parameters set to `values` (`{name: SI value}`;
        default the medians), the others as fitted with: the tangential law of an oblique
        fit. A posterior read from a dict rebuilds it by name (a law of the table; a
        user's law needs the fit)."""
        values = self.median if values is None else values
        free = {k: float(values[k]) for k in self.free}
        if self.model is not None:
            return self.model.law.replace(**free)
        from .._laws import LAWS, law
        from .._oblique.tangential import TANGENTIAL_LAWS, tangential_law

        if self.law_parameters is not None and self.law_name in TANGENTIAL_LAWS:
            return tangential_law(self.law_name, **{**self.law_parameters, **free})
        if self.law_parameters is None or self.law_name not in LAWS:
            raise ValueError(
                f"this Posterior (read from a dict) cannot rebuild its law {self.law_name!r}: "
                + (
                    "a user's law needs the fit it came from"
                    if self.law_parameters is not None
                    else "the dict holds no 'law_parameters'"
                )
            )
        return law(self.law_name, **{**self.law_parameters, **free})

    @property
    def median_law(self):
        """The law at the posterior medians of its free parameters (`law_at()`)."""
        return self.law_at()

    def draw_indices(self, n: int) -> np.ndarray:
        """The rows of at most `n` draws, evenly spaced over all of them (chains alike)."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"the number of draws must be an integer >= 1, got {n!r}")
        total = self.num_draws
        if total <= n:
            return np.arange(total)
        return np.linspace(0, total - 1, int(n)).astype(int)

    def draw_laws(self, n: int = 200) -> list:
        """The law at each of at most `n` draws, evenly thinned (`draw_indices(n)`)."""
        return [
            self.law_at({k: self.samples[k][i] for k in self.free}) for i in self.draw_indices(n)
        ]

    # ------------------------------------------------------------------ predictions

    @quietly_compiled
    def predict(
        self,
        v0=None,
        *,
        angle=None,
        speed=None,
        omega=None,
        level: float = 0.9,
        observed: bool = False,
        max_draws: int = 1000,
        key=None,
    ) -> Bands | ObliqueBands:
        """Bands of `e` and `T` (s) at the speeds `v0` (m/s): median and the `level`
        quantile band over the draws (at most `max_draws` of them, evenly thinned), each
        draw's law solved by the fit's forward model. `observed=True` adds the
        measurement noise (a band for a new measurement) to the law's band.

        The posterior of an oblique fit (`fit_oblique`) takes incidence angles instead:
        `angle` (rad from the normal, in (0, pi/2)) at `speed` (m/s) with spin `omega`
        (rad/s) before (both default to the medians of the fit's rows), and gives an
        `ObliqueBands` of `e_t`, `omega_out` (rad/s) and `angle_out` (rad).

        **Example**: `post.predict(v0=[1.0, 2.0, 4.0]).e_hi`;
        `oblique_post.predict(angle=np.deg2rad([10, 30, 50])).e_t_lo`."""
        options = dict(level=level, observed=observed, max_draws=max_draws, key=key)
        if self.model is None:  # read from a dict: no forward model (a one-line error)
            return prediction_bands(self, v0, **options)
        if isinstance(self.model, ObliqueModel):
            if v0 is not None:
                raise ValueError(
                    "this posterior is of an oblique fit: it predicts at incidence angles, "
                    "predict(angle=radians, speed=m/s), not at speeds v0"
                )
            return oblique_bands(self, angle, speed=speed, omega=omega, **options)
        if angle is not None or speed is not None or omega is not None:
            raise ValueError(
                "angle=, speed= and omega= are for the posterior of an oblique fit "
                "(fit_oblique); this one predicts at impact speeds: predict(v0=m/s)"
            )
        if v0 is None:
            raise ValueError("predict needs the impact speeds: predict(v0=m/s)")
        return prediction_bands(self, v0, **options)

    def plot(self, path=None, *, v0=None, angle=None, level: float = 0.9):
        """A pairs plot of the draws (histograms on the diagonal) and, with a forward
        model, the `level` bands over the measured data: of e and T over `v0` (m/s), or
        for an oblique fit of e_t and the spin over `angle` (rad; default around the
        data); written to `path` (PNG, PDF, ... by extension) when given. Returns the
        matplotlib Figure."""
        from .plots import plot_posterior

        return plot_posterior(self, path, v0=v0, angle=angle, level=level)

    # ------------------------------------------------------------------ text, dicts

    def summary(self) -> str:
        """Each parameter's median and 90 % interval with its unit and prior, the
        diagnostics and the evidence."""
        rows = []
        intervals = self.interval(0.9)
        for k in self.names:
            unit = self.units.get(k, "")
            lo, hi = intervals[k]
            kind, a, b = self.priors[k]
            rows.append(
                (
                    k,
                    f"{format_value(self.median[k], unit)} (90 %: {format_value(lo, unit)} to "
                    f"{format_value(hi, unit)}; prior {kind}({a:.4g}, {b:.4g}))",
                )
            )
        d = self.diagnostics
        if self.method == "nuts":
            rows.append(
                (
                    "diagnostics",
                    f"r_hat = {d['r_hat']:.4g}, ess = {d['ess']:.0f}, divergences = "
                    f"{d['divergences']} ({d['chains']} chains x {d['draws_per_chain']} draws)",
                )
            )
        else:
            laplace = f"Laplace approximation, {self.num_draws} independent draws"
            rows.append(("diagnostics", laplace))
        evidence = f"{format_value(self.log_evidence)} nats (Laplace at the mode)"
        rows.append(("log_evidence", evidence))
        noise = "normal" if self.noise == "normal" else f"Student-t (nu = {self.nu:g})"
        rows.append(("noise", noise))
        title = f"Posterior of {self.law_name} ({self.method}, {self.num_draws} draws; SI units)"
        return format_fields(title, rows)

    def to_dict(self, samples: bool = True) -> dict:
        """JSON-able: `method`, `law`, `names`, `units`, `priors`, `median`, `mean`,
        `std`, `interval90`, `map`, `diagnostics`, `log_evidence`, `noise`, `nu`,
        `law_parameters` (the fitted law's, SI), and with `samples` the draws (SI) and `z`."""
        out = {
            "method": self.method,
            "law": self.law_name,
            "names": list(self.names),
            "free": list(self.free),
            "units": dict(self.units),
            "priors": {k: list(v) for k, v in self.priors.items()},
            "median": self.median,
            "mean": self.mean,
            "std": self.std,
            "interval90": {k: list(v) for k, v in self.interval(0.9).items()},
            "map": jsonable(self.map),
            "diagnostics": jsonable(self.diagnostics),
            "log_evidence": jsonable(self.log_evidence),
            "noise": self.noise,
            "nu": self.nu,
            "law_parameters": jsonable(self.law_parameters),
        }
        if samples:
            out["samples"] = jsonable(self.samples)
            out["z"] = jsonable(self.z)
        return out

    @classmethod
    def from_dict(cls, data: dict) -> "Posterior":
        """A `Posterior` from `to_dict()` (with its samples): statistics, intervals and the
        pairs plot work; `predict` and `next_measurement` need the forward model, which
        a dict does not carry (run `posterior` on the fit again)."""
        if "samples" not in data or "z" not in data:
            raise ValueError("from_dict needs a dict written by to_dict(samples=True)")
        samples = {k: np.asarray(v, dtype=float) for k, v in data["samples"].items()}
        log_evidence = data["log_evidence"]
        return cls(
            samples=samples,
            z=np.asarray(data["z"], dtype=float),
            names=tuple(data["names"]),
            free=tuple(data["free"]),
            method=data["method"],
            law_name=data["law"],
            noise=data["noise"],
            nu=float(data["nu"]),
            units=dict(data["units"]),
            priors={k: tuple(v) for k, v in data["priors"].items()},
            map={k: float(v) for k, v in data["map"].items()},
            log_evidence=math.nan if log_evidence is None else float(log_evidence),
            diagnostics=dict(data["diagnostics"]),
            model=None,
            law_parameters=_parameters(data.get("law_parameters")),
        )

    def __repr__(self) -> str:
        return self.summary()


def _parameters(value):
    return None if value is None else {k: float(v) for k, v in value.items()}
