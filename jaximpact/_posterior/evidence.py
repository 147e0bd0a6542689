"""`compare_laws(..., by="evidence")`: the laws ranked by their marginal likelihood (the
Laplace approximation of `posterior(fit, method="laplace")`), with Bayes factors, beside
the AIC ranking of `_fit.model_choice.compare_laws`, which fits them (`by="aic"`, the
default, is that function's ranking unchanged)."""

import dataclasses
import math
import typing
import warnings

from .._fit import model_choice
from .._format import format_fields, format_value, jsonable
from .._progress import AbstractMeter, metered

if typing.TYPE_CHECKING:  # imported by the evidence ranking alone (blackjax, scipy)
    from .result import Posterior

BY = ("aic", "evidence")


@dataclasses.dataclass
class EvidenceRanking(model_choice.Ranking):
    """A `Ranking` (the law's fit, `sum_sq`, `k`, `aic`, `bic`) with its evidence:
    `log_evidence` (nats, the Laplace approximation at the posterior's mode; NaN where its
    Hessian is not negative definite), `bayes_factor` (the best law's evidence over this
    one's, `Z_best / Z`: 1 for the best, 20 and more is strong evidence against this law,
    Kass and Raftery 1995), `aic_rank` (1-based: its place in the AIC ranking, or by the
    sum of squares without sigmas) and the `posterior` (Laplace)."""

    log_evidence: float = math.nan
    bayes_factor: float = math.nan
    aic_rank: int = 0
    posterior: "Posterior | None" = None

    @property
    def log_bayes_factor(self) -> float:
        """`ln(Z_best / Z)` (nats, >= 0)."""
        return math.log(self.bayes_factor) if self.bayes_factor > 0 else math.nan

    def summary(self) -> str:
        rows = [
            ("log_evidence", f"{format_value(self.log_evidence)} nats (Laplace at the mode)"),
            (
                "bayes_factor",
                f"{format_value(self.bayes_factor)} (the best law's Z over this one's)",
            ),
            ("aic_rank", str(self.aic_rank)),
        ]
        return format_fields(f"Evidence of {self.name}", rows) + "\n" + super().summary()

    def to_dict(self) -> dict:
        """`Ranking.to_dict()` with `log_evidence`, `bayes_factor`, `log_bayes_factor` and
        `aic_rank`."""
        out = super().to_dict()
        for key in ("log_evidence", "bayes_factor", "log_bayes_factor", "aic_rank"):
            out[key] = jsonable(getattr(self, key))
        return out

    def __repr__(self) -> str:
        return self.summary()


class EvidenceRankings(list):
    """The `EvidenceRanking`s of `compare_laws(..., by="evidence")`, best first (a list),
    with `table()`: one line per law, its log evidence, Bayes factor and AIC beside it."""

    def table(self) -> str:
        weighted = bool(self) and self[0].aic is not None
        by = "AIC" if weighted else "sum_sq"
        header = ["rank", "law", "k", "log_evidence", "bayes_factor", by, f"{by} rank"]
        lines = [header]
        for rank, r in enumerate(self, start=1):
            lines.append(
                [
                    str(rank),
                    r.name,
                    str(r.k),
                    f"{r.log_evidence:.4g}",
                    f"{r.bayes_factor:.4g}",
                    f"{(r.aic if weighted else r.sum_sq):.4g}",
                    str(r.aic_rank),
                ]
            )
        widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
        text = [
            "  ".join(c.ljust(w) for c, w in zip(line, widths, strict=False)).rstrip()
            for line in lines
        ]
        text.append(
            "bayes_factor: the best law's evidence over this one's (Laplace, nats in log_evidence)"
        )
        return "\n".join(text)

    def summary(self) -> str:
        return self.table()


def compare_laws(
    *, by: str = "aic", prior: dict | None = None, progress: bool | AbstractMeter = True, **options
):
    """Fit every law of `laws` to the same measurements and rank them, best first.

    `by="aic"` (the default): `jaximpact._fit.model_choice.compare_laws`, unchanged: by AIC
    (`chi2 + 2k`) with sigmas, else by the sum of squared residuals; a list of `Ranking`.

    `by="evidence"`: the same fits, then for each law the Laplace approximation of its
    posterior (`posterior(fit, method="laplace", prior=prior[name])`: `prior` maps a law's
    name to its priors, default the documented weakly informative ones, and without sigmas
    the noise scale is sampled with its own prior), ranked by `log_evidence`, the largest
    first (a law whose evidence is NaN, its Hessian not negative definite, last). An
    `EvidenceRankings` list of `EvidenceRanking`: each with `log_evidence` (nats),
    `bayes_factor` (the best law's evidence over its own), `aic_rank` (its place by AIC)
    and its `posterior`; `.table()` prints them side by side. The evidence weighs a law's
    fit against the prior volume its parameters span, so it depends on the priors (the
    default spans three decades either side of each fitted value, the same for every law).

    Every other argument is `model_choice.compare_laws`'s: `m`, `v0`, `e`, `T`,
    `sigma_e`, `sigma_T`, `laws`, `separation`, `warn`, `max_rms_e`, `max_rms_T`,
    `workers` and `calibrate`'s options; `progress` meters the fits and then the posteriors.

    **Example**: `compare_laws(m=1.0, v0=v0s, e=es, T=Ts, sigma_e=0.01, sigma_T=0.02 * Ts,
    laws=["hertz_rate", "thornton"], by="evidence")[0].bayes_factor`.
    """
    if by not in BY:
        raise ValueError(f"by must be 'aic' or 'evidence', got {by!r}")
    if by == "aic":
        if prior is not None:
            raise ValueError("prior= is for by='evidence' (the AIC ranking has no priors)")
        return model_choice.compare_laws(progress=progress, **options)
    from .posterior import posterior

    prior = {} if prior is None else prior
    if not isinstance(prior, dict):
        raise TypeError(
            f"prior takes a dict {{law name: {{parameter: (kind, a, b)}}}}, got "
            f"{type(prior).__name__}"
        )
    rankings = model_choice.compare_laws(progress=progress, **options)
    names = [r.name for r in rankings]
    unknown = sorted(set(prior) - set(names))
    if unknown:
        raise ValueError(
            f"prior names the law {', '.join(unknown)}, not among the laws "
            f"fitted ({', '.join(names)})"
        )
    ranked = []
    with metered(progress, len(rankings), "evidence of each law") as meter:
        for aic_rank, r in enumerate(rankings, start=1):
            with warnings.catch_warnings():  # a poor mode shows as a NaN evidence
                warnings.simplefilter("ignore")
                try:
                    post = posterior(
                        r.fit, prior=prior.get(r.name), method="laplace", num_samples=500, chains=1
                    )
                except ValueError as error:  # no Gaussian at the mode: no evidence
                    if "Laplace approximation does not exist" not in str(error):
                        raise
                    post = None
            fields = {f.name: getattr(r, f.name) for f in dataclasses.fields(r)}
            evidence = math.nan if post is None else float(post.log_evidence)
            ranked.append(
                EvidenceRanking(**fields, log_evidence=evidence, aic_rank=aic_rank, posterior=post)
            )
            meter.update(1, r.name)
    ranked.sort(key=lambda r: -r.log_evidence if math.isfinite(r.log_evidence) else math.inf)
    best = ranked[0].log_evidence if ranked else math.nan
    for r in ranked:
        r.bayes_factor = math.exp(min(best - r.log_evidence, 700.0))
    return EvidenceRankings(ranked)
