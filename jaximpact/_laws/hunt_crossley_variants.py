"""Published hysteresis-damping formulas of the Hunt-Crossley family.

Every formula below gives the damping factor `D` of `F = c x^n (1 + D v)` (units s/m) from a
nominal coefficient of restitution `e` and the impact speed `v0` (m/s). They were derived
under different approximations, so the restitution they really produce differs from the
nominal `e`; `jaximpact.closed_forms.hunt_crossley_restitution` gives the exact one.
Formulas as collected in the review of Corral, Moreno, Garcia and Castejon, "Nonlinear
phenomena of contact in multibody systems dynamics: a review", Nonlinear Dyn. 104 (2021)
1269-1295, and Flores, Machado, Silva and Martins, Multibody Syst. Dyn. 25 (2011) 357-375.
"""

import jax.numpy as jnp


def hunt_crossley(e, v0):
    """Hunt and Crossley, J. Appl. Mech. 42 (1975) 440-445: `D = 3 (1 - e) / (2 v0)`."""
    return 3.0 * (1.0 - e) / (2.0 * v0)


def lankarani_nikravesh(e, v0):
    """Lankarani and Nikravesh, J. Mech. Des. 112 (1990) 369-376:
    `D = 3 (1 - e^2) / (4 v0)`."""
    return 3.0 * (1.0 - e**2) / (4.0 * v0)


def flores(e, v0):
    """Flores, Machado, Silva and Martins, Multibody Syst. Dyn. 25 (2011) 357-375:
    `D = 8 (1 - e) / (5 e v0)`."""
    return 8.0 * (1.0 - e) / (5.0 * e * v0)


def gonthier(e, v0):
    """Gonthier, McPhee, Lange and Piedboeuf, Multibody Syst. Dyn. 11 (2004) 209-233:
    `D = (1 - e^2) / (e v0)`."""
    return (1.0 - e**2) / (e * v0)


def hu_guo(e, v0):
    """Hu and Guo, Multibody Syst. Dyn. 35 (2015) 131-151: `D = 3 (1 - e) / (2 e v0)`."""
    return 3.0 * (1.0 - e) / (2.0 * e * v0)


def herbert_mcwhannell(e, v0):
    """Herbert and McWhannell, J. Eng. Ind. 99 (1977) 513-518:
    `D = 6 (1 - e) / (((2 e - 1)^2 + 3) v0)`."""
    return 6.0 * (1.0 - e) / (((2.0 * e - 1.0) ** 2 + 3.0) * v0)


def lee_wang(e, v0):
    """Lee and Wang, J. Mech. Transm. Autom. Des. 105 (1983) 534-540:
    `D = 3 (1 - e) / (4 v0)`."""
    return 3.0 * (1.0 - e) / (4.0 * v0)


def zhiying_qishao(e, v0):
    """Zhiying and Qishao, J. Dyn. Control 4 (2006) 294-298:
    `D = 3 (1 - e^2) exp(2 (1 - e)) / (4 v0)`."""
    return 3.0 * (1.0 - e**2) * jnp.exp(2.0 * (1.0 - e)) / (4.0 * v0)


def gharib_hurmuzlu(e, v0):
    """Gharib and Hurmuzlu, J. Comput. Nonlinear Dyn. 7 (2012) 031002: `D = (1/e - 1) / v0`."""
    return (1.0 / e - 1.0) / v0


# law name -> formula (its docstring holds the reference)
FORMULAS = {
    "lankarani_nikravesh": lankarani_nikravesh,
    "flores": flores,
    "gonthier": gonthier,
    "hu_guo": hu_guo,
    "herbert_mcwhannell": herbert_mcwhannell,
    "lee_wang": lee_wang,
    "zhiying_qishao": zhiying_qishao,
    "gharib_hurmuzlu": gharib_hurmuzlu,
    "hunt_crossley_nominal": hunt_crossley,
}
