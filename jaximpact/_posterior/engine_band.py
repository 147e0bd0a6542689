"""The engine's band: what an engine realises over the posterior draws. Each of a
subsample of draws (evenly thinned) is exported as a law by the caller's `realise` (the
engine's own design and response, its stepping, criterion and clamps included: one export
per draw, as `export` does for a law), and the band is the 5 and 95 % quantiles of the e
and T it realises. The engines are a higher layer: they pass `realise` in."""

import warnings

import numpy as np

from .._progress import metered

BAND_LEVEL = 0.9  # the 5-95 % band


def engine_band(post, realise, *, draws: int = 200, progress=True, level: float = BAND_LEVEL):
    """`{"e_band", "T_band", "draws", "failed", "e", "T"}`: the `level` band (5 to 95 % for
    0.9) of `realise(law) -> (e, T)` over at most `draws` evenly thinned draws of `post`
    (`Posterior.draw_laws`), each draw's `e` and `T` (s) in the order of
    `post.draw_indices(draws)` (NaN where `realise` refused the draw with a ValueError: a
    draw whose law does not separate, say) and how many failed. `progress`: a meter (True:
    the default one on stderr, False: none, or an `AbstractMeter`)."""
    laws = post.draw_laws(draws)
    es, Ts = np.full(len(laws), np.nan), np.full(len(laws), np.nan)
    with metered(progress, len(laws), "engine band over the posterior draws") as meter:
        for i, law in enumerate(laws):
            try:
                with warnings.catch_warnings():  # a draw's own warnings are the band's
                    warnings.simplefilter("ignore")
                    es[i], Ts[i] = realise(law)
            except ValueError:
                pass
            meter.update(1)
    ok = np.isfinite(es) & np.isfinite(Ts)
    if not np.any(ok):
        raise ValueError(
            f"the engine realises none of the {len(laws)} posterior draws exported (each "
            "refused, or its law does not separate): no band"
        )
    q = ((1 - level) / 2, (1 + level) / 2)
    return {
        "e_band": tuple(float(v) for v in np.quantile(es[ok], q)),
        "T_band": tuple(float(v) for v in np.quantile(Ts[ok], q)),
        "draws": int(np.sum(ok)),
        "failed": int(np.sum(~ok)),
        "e": es,
        "T": Ts,
    }
