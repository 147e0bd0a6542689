"""The promise of an export with a tangential law: the oblique impacts the engine realises
at v0 from `OBLIQUE_ANGLES` (its own stepping where it is replicated, else its continuous
laws) beside the given laws', and the warnings that go with them."""

import numpy as np

from .base import contact_mass

# the steps per contact an export with a tangential law takes at most when no step is given:
# its promise was measured against the real engines at this resolution (docs/oblique.md)
TANGENTIAL_STEPS = 400
# the incidences (degrees from the normal) an export with a tangential law reports
OBLIQUE_ANGLES = (5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0)
# how far the engine's e_t may fall from the law's before an export warns
E_T_WARN = 0.005
# how far two spheres' turning line of centres may mix their velocities before it warns
TURN_WARN = 0.01


def tangential_promise(chosen, slot, design, parameters, engine_law, tangential, given, scene):
    """`(fields, warnings)`: the `Export` fields of the oblique promise of engine `chosen`
    with its tangential model `slot` (`_oblique_promise`, for the normal `design` and the
    exported `parameters`), and the warnings that go with it: the model's `notes`, what its
    friction makes of the law (`FRICTION`) or how far its e_t departs from the law's, and
    where two spheres turn their line of centres."""
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
    """The oblique impacts at speed `scene.v0` (m/s) from `OBLIQUE_ANGLES` (no spin before)
    that the engine realises with `parameters`: its own stepping where it is replicated
    (`slot.oblique`, the mean over first-touch phases), else its continuous laws (its
    normal law `engine_law`, the exported `tangential` law) through `oblique_impact`; and
    the tangential restitution of the given law `scene.law` with the given tangential law
    `given` (None from targets). A sphere of mass `m` (kg) and radius `radius` (m) on the
    wall, or the pair's effective sphere (`two_spheres`) for two spheres; the given laws
    move it at mass `m` (the normal export's convention: the law's e and T at `m`, realised
    by the pair at `m/2` with its forces halved, the tangential ones too)."""
    from .._oblique import incidence, oblique_impact, two_spheres

    m, v0, radius, geometry, source = scene.m, scene.v0, scene.radius, scene.geometry, scene.law
    pair = _two_spheres(chosen, geometry)
    body = two_spheres(m, radius, m, radius) if pair else dict(m=m, R=radius, inertia=0.4)
    v_n, v_t = (np.asarray(v, float) for v in incidence(v0, np.deg2rad(OBLIQUE_ANGLES)))

    def continuous(normal_law, tangential_law, contact_point=0.0, ends=separation, body=body):
        # a soft spring sticks and slips many times (throw=False: a solve that still
        # fails is NaN in the promise, not an error of the export)
        rows = [
            oblique_impact(
                normal_law,
                tangential_law,
                **body,
                v_n=float(a),
                v_t=float(b),
                separation=ends,
                contact_point=contact_point,
                max_segments=64,
                throw=False,
            )
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
    """The warning of an export to an engine with friction alone (the tangential model's
    `FRICTION`): what it takes, how far its e_t falls from the law's over the angles, how
    its normal e moves."""
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
    """Two spheres passing each other turn their line of centres by about `v_t T / (2 R)`
    (rad) during a contact of duration `T` (s), which a promise computed for one body
    against a fixed normal leaves out; their normal and tangential velocities then mix by
    about `tan(theta)` times that angle. A warning where that reaches 0.01 at the largest
    angle. Measured at 75 degrees: Yade's soft pair (turn 0.075 rad, estimate 0.28) fell
    0.23 in e and 0.036 in e_t; LAMMPS's Kharaz pair (turn 0.0096 rad, estimate 0.036)
    0.0043 in e_t, 0.0077 at 45 degrees."""
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
    """Whether the export's scene is two equal spheres (a two-sphere engine, no wall)."""
    return contact_mass(chosen, 1.0, geometry) != 1.0


def _engine_share(chosen, slot, geometry) -> float:
    """`oblique_impact`'s `contact_point` for the engine's scene: each sphere's share of
    the overlap off its lever arm (the tangential model's `CONTACT_POINT`), halved for two
    equal spheres through their effective radius."""
    share = slot.CONTACT_POINT[geometry]
    return share / 2.0 if _two_spheres(chosen, geometry) else share


def _contact_point_note(chosen, slot, geometry) -> str:
    """Where the engine applies the tangential force, when not on the undeformed surface."""
    share = slot.CONTACT_POINT[geometry]
    if not share:
        return ""
    return (
        f"; {chosen.LABEL} applies the tangential force at the lever arm R - {share:g} x "
        f"(x the overlap), the law at R: oblique_impact(contact_point="
        f"{_engine_share(chosen, slot, geometry):g}) is the engine's"
    )


def _departure(oblique) -> tuple[float, str]:
    """How far the engine's e_t falls from the law's over the angles: the largest
    |e_t engine - e_t law|, and that in words."""
    gap = np.abs(np.asarray(oblique["e_t_engine"]) - np.asarray(oblique["e_t_target"]))
    k = int(np.nanargmax(gap))
    angle = oblique["angles"][k]
    return float(gap[k]), (
        f"its e_t departs from the law's by up to {gap[k]:.3g} (at {angle:g} degrees)"
    )
