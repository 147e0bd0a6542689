"""Check the shipped universal curves against independent references; writes
docs/similarity.md.

References: the Kelvin-Voigt closed form, the Hunt-Crossley restitution through Lambert W
in 50-digit arithmetic (mpmath), the undamped power spring (Beta function), and scipy's
DOP853 at rtol 1e-13 in the plain variables (x, v) for every shipped shape (`T` at
separation, `x_max` and `t_max` at v = 0, `F_max` at the root of dF/dt in compression).
Run: `python docs/similarity_accuracy.py` (about two minutes).
"""

import sys
from pathlib import Path

import jax
import mpmath
import numpy as np

jax.config.update("jax_enable_x64", True)

from jaximpact import closed_forms  # noqa: E402
from jaximpact._curves.check import scipy_impact  # noqa: E402
from jaximpact._curves.curve import OUTPUTS  # noqa: E402
from jaximpact._curves.similarity import curve_values  # noqa: E402
from jaximpact._curves.store import SHIPPED, curves_for  # noqa: E402

INTRO = """\
Without gravity and without a dry force, a law `F = c x^n + b x^p v` gives an impact that
depends on one number: in the units `x* = (m v0^2/c)^(1/(n+1))`, `t* = x*/v0` the motion is
`X'' = -X^n - beta X^p X'` with `beta = b x*^(p+1)/(m v0) = b v0 x*^(p-n)/c` (Hunt-Crossley:
`beta = 1.5 a v0`; its published variants: `beta = D v0`, a function of `e_nominal` alone).
So `e`, `T/t*`, `x_max/x*`, `t_max/t*` and `F_max/(c x*^n)` are functions of `beta` for each
shape `(n, p)` and separation criterion. jaximpact tabulates them once, as piecewise
Chebyshev series of degree 20 in `ln beta` (of the logarithm of each output, so the error
is relative down to the smallest `e`), from `beta = 1e-18` (below: the elastic limit and
its first-order slope) to `beta = 1e4` (above: the power law of the last piece), and
`impact` reads them in a few microseconds, differentiably (`jax.grad`, `jax.jacfwd`,
`jax.vmap`, float32).

**Which path runs.** `impact(..., method="auto")`:

| scene | path | why |
|---|---|---|
| Kelvin-Voigt, `g = 0`, no `ts` | closed form | exact for every damping, both criteria |
| a one-group law of the table (Kelvin-Voigt modified, the Hertz laws 12-14, Hunt-Crossley and its variants, `power`), `g = 0`, no `ts`, `rtol >= 1e-11`, no `solver` chosen | similarity | one group `beta`: the curves |
| Hertz viscous (`p = 0`, `n = 1.5`) under `"penetration"` | integrated | captured above `beta_c` (found by bisection, below): near it `T` grows without bound and `e` falls to 0, so the curves end there |
| Maxwell | integrated | a state (its force); `closed_forms.maxwell` holds where under-damped |
| Bingham and the other laws with a dry force `P` | integrated | a second group `P/(c x*^n)` and a jump at maximum compression; a two-dimensional table is not built (the integrated path already meets 1e-9) |
| any law with gravity `g > 0` | integrated | a second group `m g/(c x*^n)`; tiny for most real contacts, but the integrated path is exact at no loss |
| `ts=` (time histories), a custom law | integrated | the curves hold the five outputs, not the motion; a custom law has no known group |

`method="similarity"` insists and raises a `ValueError` that says which of these reasons
holds; `method="integrate"` always integrates. The same curves serve `impact_batch` (rows of
one shape: Hunt-Crossley's `n` the same on every row), the maps, the design studies, the
command line, and `calibrate` (below). A shape that is not shipped (Hunt-Crossley with
another `n`, `law("power", n=..., p=...)`) is built on first use (a progress bar; tens of
seconds) and kept in `$JAXIMPACT_CURVES_DIR` (default `~/.cache/jaximpact/curves`); a cache
file that does not match its checksum, format or shape is rebuilt, never trusted.

**Calibration on the curves.** `calibrate` of a one-group law inverts the monotone `e(beta)`
(bisection in `ln beta`), reads `T/t*` at that `beta` for the stiffness (`t* = T/tau`,
`x* = v0 t*`, `c = m v0^2/x*^(n+1)`), and sets the damping from `beta` (linear in it at fixed
`c`). At one speed with `e` and `T` that is the fit: no optimiser runs (`iterations = 0`). At
several speeds the start comes the same way and the least squares runs over the curves.

**Where the curves are noisy.** Under the force criterion at heavy damping (`beta` above
about 30 for the `p = 0` laws, a few hundred for the others) the body creeps out while the
contact force stays within rounding of zero, so the instant it vanishes is ill-conditioned:
`T` there is reproducible only to the `tail` estimates below (the reference integrator itself
scatters by that much); `e`, `x_max`, `t_max`, `F_max` keep their accuracy.
"""


def curve(key, beta):
    return np.asarray(curve_values(curves_for(key), jax.numpy.asarray(beta), (0, 1, 2, 3, 4)))


def lambert_restitution(alpha):
    mpmath.mp.dps = 50
    a = mpmath.mpf(alpha)
    return float((1 + mpmath.lambertw(-(1 + a) * mpmath.exp(-(1 + a)), 0).real) / a)


def main():
    rng = np.random.default_rng(0)
    lines = [
        "# Universal curves: which path an impact takes, and how accurate the curves are",
        "",
        INTRO,
        "",
        "## Accuracy",
        "",
        "Written by `python docs/similarity_accuracy.py`. Relative errors (absolute where the",
        "value is below 1e-12), largest over log-uniform random `beta` in each band.",
        "",
    ]
    for key in SHIPPED:
        c = curves_for(key)
        lines.append(
            f"- `{key.name}`: {len(c.breaks) - 1} pieces of degree 20 up to beta = "
            f"{c.beta_max:.4g}"
            + (f", captured above beta = {c.capture:.12g} (not served)" if c.capture else "")
            + f"; largest tail coefficient {c.tail.max():.1e} (its error estimate)"
        )
    lines.append("")
    bands = [(1e-12, 1e-3), (1e-3, 1.0), (1.0, 30.0), (30.0, 1e3), (1e3, 1e4)]
    lines += ["## Against scipy DOP853 at rtol 1e-13", ""]
    lines += [
        "| shape | beta | e | T/t* | x_max/x* | t_max/t* | F_max |",
        "|---|---|---|---|---|---|---|",
    ]
    for key in SHIPPED:
        curves = curves_for(key)
        for lo, hi in bands:
            hi = min(hi, curves.beta_max)
            if lo >= hi:
                continue
            betas = np.exp(rng.uniform(np.log(lo), np.log(hi), 6))
            worst = np.zeros(5)
            for beta in betas:
                ref = np.array(scipy_impact(beta, key.n, key.p, key.separation))
                got = curve(key, beta)
                err = np.abs(got - ref) / np.maximum(np.abs(ref), 1e-12)
                worst = np.maximum(worst, err)
            lines.append(
                f"| {key.name} | {lo:g}-{hi:g} | " + " | ".join(f"{w:.1e}" for w in worst) + " |"
            )
            print(lines[-1], flush=True)
    lines += ["", "## Against closed forms", ""]
    lines += ["| reference | beta | quantity | largest error |", "|---|---|---|---|"]
    kv = [k for k in SHIPPED if (k.n, k.p) == (1.0, 0.0)][0]
    capture = curves_for([k for k in SHIPPED if curves_for(k).capture][0]).capture
    lines += [
        f"| capture threshold, Hertz viscous under penetration | {capture:.12g} | beta_c | bisection to 1e-12 |"
    ]
    for lo, hi in bands:
        betas = np.exp(rng.uniform(np.log(lo), np.log(hi), 40))
        worst = np.zeros(5)
        for beta in betas:
            exact = closed_forms.kelvin_voigt(1.0, beta, 1.0, 1.0, "force")
            ref = np.array([float(exact[name]) for name in ("e", "T", "x_max", "t_max", "F_max")])
            worst = np.maximum(worst, np.abs(curve(kv, beta) - ref) / np.maximum(ref, 1e-12))
        for name, w in zip(OUTPUTS, worst, strict=True):
            lines.append(f"| Kelvin-Voigt closed form | {lo:g}-{hi:g} | {name} | {w:.1e} |")
    hc = [k for k in SHIPPED if k.n == k.p == 1.5][0]
    for lo, hi in bands:
        alphas = np.exp(rng.uniform(np.log(lo), np.log(hi), 40))
        worst = max(
            abs(curve(hc, a)[0] - lambert_restitution(a)) / max(lambert_restitution(a), 1e-12)
            for a in alphas
        )
        lines.append(
            f"| Hunt-Crossley e, Lambert W (50 digits) | {lo:g}-{hi:g} | e | {worst:.1e} |"
        )
    for key in SHIPPED:
        spring = closed_forms.power_spring(1.0, key.n, 1.0, 1.0)
        got = curve(key, 0.0)
        for name, index in (("T", 1), ("x_max", 2), ("t_max", 3), ("F_max", 4)):
            ref = float(spring[name])
            lines.append(
                f"| undamped power spring | 0 | {key.name} {name} | {abs(got[index] - ref) / ref:.1e} |"
            )
    lines += ["", "Machine: " + " ".join(sys.version.split()[:1]) + f", jax {jax.__version__}.", ""]
    Path(__file__).with_name("similarity.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
