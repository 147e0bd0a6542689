"""Uncertainty of a fit: priors, the likelihood built from a fit's forward model, the
Laplace approximation, NUTS (blackjax), the `Posterior` record, prediction bands and the
next measurement, for the results of `calibrate`, `fit_bounces` and `fit_oblique`. Imports
`_fit`, `_oblique`, `_curves` and `_laws`. Its modules are
imported where used (`jaximpact.posterior` is `.posterior.posterior`): this package imports
none of them, so that `compare_laws`'s AIC ranking (`.evidence`) does not load blackjax,
scipy and the oblique fit (0.8 s of its first call)."""
