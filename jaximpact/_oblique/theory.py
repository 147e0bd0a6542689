"""The rigid-body impulse theory of an oblique impact (a sphere on a plane, Coulomb
friction `mu`, normal restitution `e`): the limit that `oblique_impact` reaches exactly
where the contact slides throughout, and the rolling (no-slip) end state otherwise.

With the normal impulse `P_n = m (1 + e) v_n` and `I = inertia m R^2`, a contact that slides
throughout takes the tangential impulse `-s mu P_n` (`s` the sense of the slip
`u = v_t - R omega`), and the contact point's slip changes by
`-s mu P_n (1/m + R^2/I) = -s mu (1 + e) v_n (1 + 1/inertia)`. It slides throughout where
that change does not exceed `|u|`, i.e. `|u| >= mu (1 + e) v_n (1 + 1/inertia)` (a solid
sphere: `tan(theta) >= 3.5 mu (1 + e)` at `omega = 0`); otherwise the rigid theory ends
rolling, `u_out = 0`, `v_t_out = v_t - u inertia / (1 + inertia)` (`5/7 v_t` from rest).
Maw, Barber & Fawcett, Wear 38 (1976) 101; notes/contact-physics.md 4.1.
"""

import jax.numpy as jnp


def rigid_oblique(*, mu, e, v_n, v_t, R, omega=0.0, inertia=0.4) -> dict:
    """The rigid-body outcome (SI units, radians): a dict of `v_t_out`, `omega_out`,
    `u_out`, `e_t`, `e_t_contact`, `angle_out`, `angle_out_contact`, and `sliding`
    (whether the contact slides throughout).

    **Example**: `rigid_oblique(mu=0.092, e=0.98, v_n=3.0, v_t=2.5, R=2.5e-3)["e_t"]`.
    """
    mu, e, v_n, v_t, R, omega, inertia = (
        jnp.asarray(a, dtype=float) for a in (mu, e, v_n, v_t, R, omega, inertia)
    )
    u = v_t - R * omega
    reach = mu * (1.0 + e) * v_n * (1.0 + 1.0 / inertia)  # the slip a full slide removes
    sliding = jnp.abs(u) >= reach
    change_t = jnp.where(
        sliding, -jnp.sign(u) * mu * (1.0 + e) * v_n, -u * inertia / (1.0 + inertia)
    )
    v_t_out = v_t + change_t
    omega_out = omega - change_t / (inertia * R)
    u_out = v_t_out - R * omega_out
    v_n_out = e * v_n
    return dict(
        v_t_out=v_t_out,
        omega_out=omega_out,
        u_out=u_out,
        e_t=v_t_out / v_t,
        e_t_contact=u_out / u,
        angle_out=jnp.arctan2(v_t_out, v_n_out),
        angle_out_contact=jnp.arctan2(u_out, v_n_out),
        sliding=sliding,
    )
