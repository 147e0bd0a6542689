"""Universal curves of one-group impacts: the similarity path of `impact` and `calibrate`.

A law `F = c x^n + b x^p v` without gravity or dry force gives an impact that depends on one
number `beta` alone; its outputs are tabulated once per shape as Chebyshev series in
`ln beta` (`build`, `store`) and evaluated in JAX (`similarity`).
"""
