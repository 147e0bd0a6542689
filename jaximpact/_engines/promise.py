"""An export's tangential promise: the oblique impacts the engine realises at v0 from
`OBLIQUE_ANGLES` (its stepping where replicated, else its continuous laws) beside the given
laws', and their warnings."""

import numpy as np

from .base import contact_mass

TANGENTIAL_STEPS = 400  # steps per contact at most: the promise's, measured (docs/oblique.md)
OBLIQUE_ANGLES = (5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0)  # degrees from the normal
E_T_WARN = 0.005  # how far the engine's e_t may fall from the law's unwarned
TURN_WARN = 0.01  # how far two spheres' turning line of centres may mix v_n, v_t unwarned


def tangential_promise(chosen, slot, design, parameters, engine_law, tangential, given, scene):
    """`(fields, warnings)`: the oblique promise of `chosen`'s tangential model `slot` with
    `parameters`, and its warnings (the model's notes, its friction or e_t departure, two
    spheres turning)."""
    oblique = _oblique_promise(
        chosen, slot, parameters, engine_law, design.separation, tangential, given, scene
    )
    geometry = scene.geometry
    warnings = slot.notes(parameters, tangential)
    if slot.FRICTION is not None:
        warnings.append(_friction_note(slot, given, oblique))
    elif scene.law is not None and (departure := _departure(oblique))[0] > E_T_WARN:
        warnings.append(departure[1] + _contact_point_note(chosen, slot, geometry))
    if _two_spheres(chosen, geometry):
        warnings += _turning_note(design.T, v0=scene.v0, radius=scene.radius)
    return oblique, warnings


def _oblique_promise(chosen, slot, parameters, engine_law, separation, tangential, given, scene):
    """The oblique impacts at `scene.v0` from `OBLIQUE_ANGLES` (no spin before) the engine
    realises: its stepping (`slot.oblique`, phase means) or its continuous laws
    (`engine_law`, `tangential`) through `oblique_impact`; and the given laws' e_t at mass
    `m` (None from targets). The body: the sphere, or for two spheres the pair's effective
    one."""
    from .._oblique import incidence, oblique_impact, two_spheres

    m, v0, radius, geometry, source = scene.m, scene.v0, scene.radius, scene.geometry, scene.law
    pair = _two_spheres(chosen, geometry)
    body = two_spheres(m, radius, m, radius) if pair else dict(m=m, R=radius, inertia=0.4)
    v_n, v_t = (np.asarray(v, float) for v in incidence(v0, np.deg2rad(OBLIQUE_ANGLES)))

    def continuous(normal_law, tangential_law, contact_point=0.0, ends=separation, body=body):
        # a soft spring sticks and slips many times (throw=False: a solve that still
        # fails is NaN in the promise, not an error of the export)
        how = dict(separation=ends, contact_point=contact_point, max_segments=64, throw=False)
        rows = [
            oblique_impact(normal_law, tangential_law, **body, v_n=float(a), v_t=float(b), **how)
            for a, b in zip(v_n, v_t, strict=True)
        ]
        return tuple(
            np.array([[float(getattr(r, k)) for r in rows] for k in ("e", "e_t", "omega_out")])
        )

    stepped = slot.oblique(parameters, m=m, radius=radius, v_n=v_n, v_t=v_t)
    if stepped is None:
        realised = slot.realised(parameters, tangential)
        e_n, e_t, omega = continuous(engine_law, realised, _engine_share(chosen, slot, geometry))
    else:
        e_n, e_t, omega = (np.asarray(a).mean(axis=-1) for a in stepped)
    if pair:  # each sphere's spin: both turn alike, R* W* = R (w1 + w2) for the pair's slip
        omega = omega * body["R"] / (2.0 * radius)
    # the law's own: under the force criterion, as its e and T (`_targets`), at mass m
    target = None
    if source is not None:
        at_m = dict(body, m=m)
        target = tuple(map(float, continuous(source, given, ends="force", body=at_m)[1]))
    return dict(
        tangential=tangential,
        angles=OBLIQUE_ANGLES,
        e_t_engine=tuple(map(float, e_t)),
        omega_engine=tuple(map(float, omega)),
        e_n_engine=tuple(map(float, e_n)),
        e_t_target=target,
    )


def _friction_note(slot, tangential, oblique) -> str:
    """The warning of friction alone (`FRICTION`): its mu, normal e and e_t departure."""
    angles, e_n = np.asarray(oblique["angles"]), np.asarray(oblique["e_n_engine"])
    note = (
        f"{slot.FRICTION} (mu = {float(tangential.params['mu']):.4g} of "
        f"{tangential.name}); over {angles.min():g}-{angles.max():g} degrees its normal e "
        f"runs {e_n.min():.4g} to {e_n.max():.4g}"
    )
    if oblique["e_t_target"] is not None:
        note += ", and " + _departure(oblique)[1]
    return note


def _turning_note(T: float, *, v0: float, radius: float) -> list[str]:
    """Two spheres turn their line of centres by about `v_t T / (2 R)` (rad) in contact (the
    promise holds it fixed), mixing v_n and v_t by `tan(theta)` times that: a warning where
    that reaches `TURN_WARN`. Measured at 75 degrees: Yade's soft pair (turn 0.075 rad,
    estimate 0.28) fell 0.23 in e, 0.036 in e_t; LAMMPS's Kharaz pair (0.0096 rad, 0.036)
    0.0043 in e_t."""
    theta = np.deg2rad(max(OBLIQUE_ANGLES))
    turn = v0 * np.sin(theta) * T / (2.0 * radius)
    mixing = float(np.tan(theta) * turn)
    if mixing < TURN_WARN:
        return []
    return [
        f"two spheres turn their line of centres by about {turn:.2g} rad during contact "
        f"at {max(OBLIQUE_ANGLES):g} degrees (v_t T / 2R), which the promise holds fixed: "
        f"the engine's e may fall up to about {mixing:.2g} below it there, its e_t and spin "
        "by less (and all less at smaller angles); a wall (geometry='wall') or a shorter "
        "contact keeps it small"
    ]


def _two_spheres(chosen, geometry) -> bool:
    """Whether the scene is two equal spheres."""
    return contact_mass(chosen, 1.0, geometry) != 1.0


def _engine_share(chosen, slot, geometry) -> float:
    """`oblique_impact`'s `contact_point`: `slot.CONTACT_POINT`, halved for two spheres."""
    share = slot.CONTACT_POINT[geometry]
    return share / 2.0 if _two_spheres(chosen, geometry) else share


def _contact_point_note(chosen, slot, geometry) -> str:
    """Where the engine applies the tangential force, if not at R."""
    share = slot.CONTACT_POINT[geometry]
    if not share:
        return ""
    return (
        f"; {chosen.LABEL} applies the tangential force at the lever arm R - {share:g} x "
        f"(x the overlap), the law at R: oblique_impact(contact_point="
        f"{_engine_share(chosen, slot, geometry):g}) is the engine's"
    )


def _departure(oblique) -> tuple[float, str]:
    """The largest |e_t engine - e_t law| over the angles, and that in words."""
    gap = np.abs(np.asarray(oblique["e_t_engine"]) - np.asarray(oblique["e_t_target"]))
    k = int(np.nanargmax(gap))
    angle = oblique["angles"][k]
    return float(gap[k]), (
        f"its e_t departs from the law's by up to {gap[k]:.3g} (at {angle:g} degrees)"
    )
