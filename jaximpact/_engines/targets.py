"""What an export aims at: its inputs checked, the law's e and T (or the targets), the e(v)
and T(v) of the engine and the law, and the line for a law the engine lacks."""

import numpy as np

from .._checks import check_scale
from .base import AbstractEngine, Design, Scene
from .materials import check_poisson, check_positive, check_restitution

SPEED_FACTORS = (0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0)  # an export's speeds, in units of v0


def law_of(law_or_fit):
    from .._laws import AbstractLaw

    if isinstance(law_or_fit, AbstractLaw):
        return law_or_fit
    inner = getattr(law_or_fit, "law", None)
    if isinstance(inner, AbstractLaw):
        return inner
    raise ValueError(
        "export needs a law (jaximpact.law(...)), a fit (calibrate's result) or None with "
        f"e= and T=; got {type(law_or_fit).__name__}"
    )


def curve(law, m, speeds, separation):
    from .._solve.impact import impact

    es, Ts = [], []
    for v in speeds:
        r = impact(law, m=m, v0=float(v), separation=separation)
        es.append(float(r.e))
        Ts.append(float(r.T))
    return tuple(es), tuple(Ts)


def inputs(m, v0, timestep, poisson):
    """`(m, v0, timestep, poisson)` checked (kg, m/s, s or None, - or None)."""
    m = check_scale("m", check_positive("m", m, "kg"), "kg")
    v0 = check_scale("v0", check_positive("v0", v0, "m/s"), "m/s")
    if timestep is not None:
        timestep = check_positive("timestep", timestep, "s")
    if poisson is not None:
        poisson = check_poisson("poisson", poisson)
    return m, v0, timestep, poisson


def targets(law_or_fit, *, e, T, m: float, v0: float, speeds=None):
    """`(source, target_e, target_T)`: the law (None from targets) and the e and T (s) aimed
    at: the targets, or the law's at `m` (kg), `v0` (m/s); with `speeds` (m/s) the middle of
    its e over them. One-line ValueErrors: neither or both given, no separation."""
    if law_or_fit is None:
        if e is None:
            raise ValueError("export needs a law or fit, or the target e= (and T=)")
        return None, check_restitution(e), None if T is None else check_positive("T", T, "s")
    if e is not None or T is not None:
        raise ValueError("give either a law (or fit) or the targets e= and T=, not both")
    source = law_of(law_or_fit)
    from .._solve.impact import impact

    if speeds is not None:
        es, _ = curve(source, m, speeds, "force")
        if not max(es) > 0:
            raise ValueError("the law does not separate at any of these speeds: no engine target")
        return source, 0.5 * (max(es) + min(es)), float(impact(source, m=m, v0=v0).T)
    result = impact(source, m=m, v0=v0)
    if int(result.status) != 0:
        below = ""
        # an adhesive law with a closed-form sticking speed (jkr; dmt's has none)
        if hasattr(source, "sticking_speed"):
            below = f", below its sticking speed {float(source.sticking_speed(m)):.4g} m/s"
        raise ValueError(
            f"the law does not separate at this m and v0 (e = 0{below}): no engine target"
        )
    return source, float(result.e), float(result.T)


def responses(engine_law, m_engine: float, out: Design, stepping, scene: Scene, speeds=None):
    """`(fields, note)`: the `Export`'s `speeds` (`v0` times `SPEED_FACTORS`, or those
    given), `e_engine`, `T_engine` (the `stepping`'s phase means, else `engine_law` on
    `m_engine`, kg), the law's `e_target`, `T_target` at `scene.m`, and a warning where the
    two e(v) part by more than 0.02."""
    source, m, v0 = scene.law, scene.m, scene.v0
    speeds = tuple(v0 * f for f in SPEED_FACTORS) if speeds is None else tuple(speeds)
    if stepping is None:  # the continuous plant, or a stepper not replicated (Chrono)
        e_engine, T_engine = curve(engine_law, m_engine, speeds, out.separation)
    else:  # what the engine's stepping realises: the mean over first-touch phases
        runs = [stepping.run(v) for v in speeds]
        e_engine = tuple(float(np.mean(es)) for es, _ in runs)
        T_engine = tuple(float(np.mean(Ts)) for _, Ts in runs)
    fields = dict(speeds=speeds, e_engine=e_engine, T_engine=T_engine)
    if source is None:
        return fields, None
    e_target, T_target = curve(source, m, speeds, "force")
    fields.update(e_target=e_target, T_target=T_target)
    spread = max(abs(a - b) for a, b in zip(e_engine, e_target, strict=True))
    if spread <= 0.02:
        return fields, None
    return fields, (
        f"the engine's e(v) departs from the law's by up to {spread:.3f} between "
        f"{speeds[0]:.3g} and {speeds[-1]:.3g} m/s: the export is exact at v0 only"
    )


def normal_model(chosen: AbstractEngine, source):
    """`(model, lacked)`: `chosen`'s normal model for the law `source` (its row of `NORMAL`,
    else the first) and whether the engine lacks a plastic or adhesive law (`LawSpec.kind`)."""
    default = next(iter(chosen.NORMAL.values()))
    if source is None:
        return default, False
    own = chosen.NORMAL.get(source.name)
    if own is not None:
        return own, False
    return default, source.spec is not None and source.spec.kind != "viscoelastic"


def given_speeds(v0, lacked, chosen: AbstractEngine):
    """`(v0, speeds)`: one speed (m/s) and None, or for a law the engine lacks the speeds'
    geometric middle and the speeds, sorted."""
    if isinstance(v0, str) or np.ndim(v0) == 0:
        return v0, None
    if not lacked:
        raise ValueError(
            f"v0 must be one speed (m/s) for this law and {chosen.LABEL}; a list of speeds "
            "is for a law with a contact state the engine lacks (thornton; jkr but for "
            "LAMMPS), whose nearest engine law is then set over them"
        )
    speeds = sorted(check_positive("v0", v, "m/s") for v in np.ravel(v0))
    if len(speeds) < 2 or speeds[0] == speeds[-1]:
        raise ValueError("give two or more different speeds in v0=[...] (m/s), or one speed")
    return float(np.sqrt(speeds[0] * speeds[-1])), tuple(speeds)


def nearest(chosen: AbstractEngine, normal, scene: Scene, fields, target_e, *, fitted) -> str:
    """The line for a law with a contact state that `chosen` lacks: its nearest (`normal`'s
    `NEAREST`), how it was set (`fitted`: over the speeds given), the worst |de|."""
    source, v0 = scene.law, scene.v0
    speeds, mine, law = fields["speeds"], fields["e_engine"], fields["e_target"]
    gaps = [abs(a - b) for a, b in zip(mine, law, strict=True)]
    worst = int(np.argmax(gaps))
    lacked = f"{source.name} law ({source.spec.equation}; e(v) from a contact state)"
    how = (
        f"set to e = {target_e:.3g} (the middle of the law's {min(law):.3g} to "
        f"{max(law):.3g}) and the law's T at {v0:.3g} m/s"
        if fitted
        else f"set to the law's e and T at v0 = {v0:.3g} m/s"
    )
    tail = "" if fitted else "; pass v0=[...] (m/s) to fit e over the speeds you need"
    return (
        f"{chosen.LABEL} has no {lacked}; the nearest is {normal.NEAREST}, {how}: from "
        f"{speeds[0]:.3g} to {speeds[-1]:.3g} m/s its e departs from the law's by up to "
        f"{gaps[worst]:.3g} (|de| at {speeds[worst]:.3g} m/s){tail}"
    )


def check_scales(m: float, v0: float, T: float) -> None:
    """A one-line ValueError where float64 cannot hold `m / T^2`, `(T / 1e5)^2`, `v0 T` or
    `m v0 / T`."""
    with np.errstate(all="ignore"):
        m_, v_, T_ = np.float64(m), np.float64(v0), np.float64(T)
        scales = (m_ / T_**2, (T_ / 1e5) ** 2, v_ * T_, m_ * v_ / T_)
    tiny = np.finfo(np.float64).tiny
    if not all(np.isfinite(s) and s > tiny for s in scales):
        raise ValueError(
            f"T = {T:g} s, m = {m:g} kg and v0 = {v0:g} m/s give a stiffness, step or force "
            "that float64 cannot hold; are they in s, kg and m/s?"
        )
