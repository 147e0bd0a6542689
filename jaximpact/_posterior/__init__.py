"""Uncertainty of a fit: priors, the likelihood built from a fit's forward model, the
Laplace approximation, NUTS (blackjax), the `Posterior` record, prediction bands and the
next measurement, for the results of `calibrate`, `fit_bounces` and `fit_oblique`. Imports
`_fit`, `_oblique`, `_curves` and `_laws`."""

from .next_measurement import (
    NextMeasurement as NextMeasurement,
    next_measurement as next_measurement,
)
from .posterior import PosteriorWarning as PosteriorWarning, posterior as posterior
from .result import Posterior as Posterior
