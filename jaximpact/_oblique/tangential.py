"""Tangential contact laws: a spring in the tangent plane whose force is limited by
Coulomb's `mu |F_n|`, one row of `TANGENTIAL_LAWS` (`TangentialSpec`) and one final class
per law, and `tangential_law(name, **params)` that builds them.

Sign convention (shared/DESIGN.md, "Oblique impacts"): the contact point of the sphere
slips over the surface at `u = v_t - R omega` (m/s); the tangential force on the sphere
`F_t` (N) opposes the spring's stretch. While the contact sticks the spring is loaded by
the slip; once `|F_t|` reaches `mu |F_n|` the contact slides with `F_t = -s mu |F_n|`,
`s` the sense of sliding, and the spring is held at that limit (`oblique_impact`).

Two ways of keeping the spring's history (the engines differ; LAMMPS `pair granular`
names them):

- displacement history: the spring's stretch `delta` is the state, `delta' = u` while
  sticking, `F_t = -k_t(x) delta` (LAMMPS `linear_history` and `mindlin`; Cundall & Strack
  1979). Where the stiffness changes with the overlap (Mindlin) the force follows it
  without any slip.
- force history: the force is the state, `F_t' = -k_t(x) u` while sticking (LAMMPS
  `mindlin/force`; the incremental Hertz-Mindlin of Yade's `Law2_ScGeom_MindlinPhys_Mindlin`,
  Thornton et al. 2011's "no-slip" model). Its first-touch stick criterion is Maw, Barber
  & Fawcett's: the contact starts sticking where `psi_1 < 1` (notes/contact-physics.md 4.1).

Each Mindlin history also comes rescaled on unloading (LAMMPS `mindlin_rescale`,
`mindlin_rescale/force`: gran_sub_mod_tangential.cpp scales the history by `a_new / a_old`
at each step where the contact radius `a` shrinks): while sticking, `Q' = (rate above) +
Q a'/a` where `a' < 0`, `a'/a = x'/(2x)` for Mindlin's `a = (R x)^0.5`. The stretch then
shrinks with the contact, so a displacement history no longer makes elastic energy as
`k_t` falls.

Damping on the slip while sticking, in the two conventions the engines use:

- `linear_history`'s constant `ct` (N s/m), as LAMMPS adds its tangential damper: the
  damper is part of the force that Coulomb's limit caps, and the spring is held so that
  spring plus damper sit at the limit while sliding.
- the Mindlin laws' `beta`, the damper of EDEM's and LIGGGHTS' Hertz-Mindlin,
  `2 (5/6)^0.5 beta (m k_t(x))^0.5` (N s/m; `m` the sphere's mass, the pair's effective one
  for two spheres; `beta = -ln e / (pi^2 + ln^2 e)^0.5` from a restitution `e`), growing as
  `x^(1/4)`: as in LIGGGHTS' `tangential history`, Coulomb's test is on the spring's force
  alone, and the damper acts only while sticking. (With the damper inside the test, a
  Hertz-Mindlin contact could neither stick nor slide at first touch: the damper, `x^(1/4)`,
  outgrows the limit, `x^(3/2)`, while the held spring's sliding rate is negative.)
"""

import abc
import dataclasses
import warnings
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import check_nonnegative, check_positive, is_traced
from .._choices import unknown_name
from .._powers import safe_pow

HISTORIES = ("displacement", "force")


@dataclasses.dataclass(frozen=True)
class TangentialSpec:
    """One row of the tangential law table.

    `parameters`: the law's own parameters, as the law object holds them (arrays; what a
    fit frees); `inputs`: what `tangential_law` also accepts and converts (Mindlin's `G`,
    `nu`, `G2`, `nu2` to `G_star`); `damper_tested`: Coulomb's limit caps spring plus
    damper (LAMMPS's convention), else the spring alone (LIGGGHTS', EDEM's). `history`:
    `"displacement"` or `"force"` (module docstring); `power`: the exponent of the overlap
    in the stiffness, `k_t = k0 x^power` (0 for a constant spring, 0.5 for Mindlin's
    `8 G* sqrt(R x)`); `rescaled`: the history shrinks with the contact radius on
    unloading (module docstring); `engines`: where the same variant is found.
    """

    name: str
    formula: str
    parameters: tuple[str, ...]
    units: dict[str, str]
    reference: str
    history: str
    power: float
    engines: str
    positive: tuple[str, ...]
    defaults: dict[str, float] = dataclasses.field(default_factory=dict)
    inputs: tuple[str, ...] = ()
    damper_tested: bool = True
    rescaled: bool = False

    def __post_init__(self):
        if self.history not in HISTORIES:
            raise ValueError(f"row {self.name!r}: history must be one of {HISTORIES}")


# the overlap (units of x*) below which a rescaled history's shrink is taken in closed form
# (`TangentialDynamics.stick_rate`, `owed`)
RESCALE_FLOOR = 1e-9


class TangentialDynamics(eqx.Module):
    """A tangential law in the normal contact's units (`x*`, `t*`, force `m v_n^2 / x*`,
    velocity `v_n`): stiffness `K(X) = k0 X^power`, damping `D(X) = damping X^damping_power`
    on the slip `U` while sticking, friction `mu`, and `inv_inertia = m R^2 / I`;
    `damper_tested`: Coulomb's limit caps spring plus damper (else the spring alone). The
    spring state `Q` is the stretch `delta / x*` (displacement history) or the elastic force
    itself (force history)."""

    mu: Array
    k0: Array
    damping: Array
    inv_inertia: Array
    power: float = eqx.field(static=True)
    history: str = eqx.field(static=True)
    damping_power: float = eqx.field(static=True, default=0.0)
    damper_tested: bool = eqx.field(static=True, default=True)
    rescaled: bool = eqx.field(static=True, default=False)

    def damper(self, x):
        """`D(X)`: 0 outside the surface where it grows with the overlap."""
        if self.damping_power == 0:
            return self.damping + jnp.zeros_like(x)
        return self.damping * safe_pow(x, self.damping_power)

    def stiffness(self, x):
        """`K(X)`: 0 outside the surface (Mindlin), without a NaN in value or gradient."""
        if self.power == 0:
            return self.k0 + jnp.zeros_like(x)
        return self.k0 * safe_pow(x, self.power)

    def owed(self, x):
        """The shrink a rescaled history still owes below `RESCALE_FLOOR x*`, where its
        state no longer follows the contact radius: `(x / floor)^0.5` there, else 1 (and 1
        for a history that is not rescaled)."""
        if not self.rescaled:
            return 1.0
        # safe_pow: 0 with a zero derivative outside the surface (a square root of the
        # clipped 0 has an infinite one, and a solve that steps to x = -1e-12 x* at the
        # contact's end took NaN from its rate there)
        return jnp.minimum(safe_pow(x / RESCALE_FLOOR, 0.5), 1.0)

    def elastic(self, q, x):
        """The spring's force on the body."""
        force = -self.stiffness(x) * q if self.history == "displacement" else q
        return force * self.owed(x)

    def trial(self, q, x, u):
        """The force the contact would carry if it stuck: spring plus damper."""
        return self.elastic(q, x) - self.damper(x) * u

    def tested(self, q, x, u):
        """The force Coulomb's limit caps: the trial force, or the spring's alone."""
        return self.trial(q, x, u) if self.damper_tested else self.elastic(q, x)

    def stick_rate(self, q, x, u, v):
        """`dQ/dtau` while sticking, at overlap `x` closing at `v` (`X' = v`): rescaled,
        `Q` shrinks as the contact radius, `Q v / (2x)` where `v < 0`."""
        rate = u if self.history == "displacement" else -self.stiffness(x) * u
        if not self.rescaled:
            return rate
        # the shrinking rate, `v/(2x)`, grows without bound as the overlap closes, which
        # no explicit step outruns where the contact sticks to the end (it ran out of
        # steps): below `RESCALE_FLOOR x*` the state stops shrinking and the force takes
        # the shrink still owed, `(x / floor)^0.5`, in closed form (`owed`), so that it
        # falls to 0 with the contact as the limit does (a state merely held there kept
        # a residue above the limit, 0 at the surface, and such contacts failed)
        above = x >= RESCALE_FLOOR
        shrink = jnp.minimum(v, 0.0) / (2.0 * jnp.where(above, x, 1.0))
        return rate + jnp.where(above, q * shrink, 0.0)

    def held(self, sense, cap, x, u):
        """The spring state that puts the tested force at the limit, `tested = -sense cap`
        (where sliding stops, the spring resumes from there). Displacement history:
        `(sense cap - D u) / K` (the damper tested; else `sense cap / K`), 0 where `K = 0`
        (outside the surface); a rescaled history's over the shrink it still owes."""
        damped = self.damper(x) * u if self.damper_tested else jnp.zeros_like(u)
        owed = self.owed(x) + jnp.zeros_like(x)
        if self.history == "force":
            state = -sense * cap + damped
            inside = owed > 0
            return jnp.where(inside, state / jnp.where(inside, owed, 1.0), 0.0)
        k = self.stiffness(x) * owed
        inside = k > 0
        return jnp.where(inside, (sense * cap - damped) / jnp.where(inside, k, 1.0), 0.0)


class AbstractTangentialLaw(eqx.Module):
    """A tangential contact law. Its array fields are its parameters (what a fit updates).

    What every tangential law declares: `name`, its row `spec`, `params` (arrays by name);
    its stiffness `stiffness(x, R=...)` (N/m) at overlap `x` (m), its friction
    coefficient `mu`, its damping (`damping_scale`), the history it keeps
    (`spec.history`), and `dynamics(...)`, its equations in a normal contact's units.
    Concrete laws are final: `LinearHistoryLaw`, `MindlinLaw`.
    """

    name: eqx.AbstractVar[str]
    spec: eqx.AbstractVar[TangentialSpec]
    params: eqx.AbstractVar[dict[str, Array]]
    # the parameters a force is proportional to (`forces_scaled`)
    FORCE_PARAMETERS: ClassVar[tuple[str, ...]] = ()

    def __repr__(self):
        """The call that builds the law, with its values in SI units:
        `tangential_law('mindlin', G_star=1.35e10 Pa, mu=0.3, beta=0)`."""
        from .._format import call_text

        return call_text("tangential_law", repr(self.name), self.params, self.spec.units)

    @abc.abstractmethod
    def stiffness(self, x, *, R):
        """The tangential stiffness `k_t` (N/m) at overlap `x` (m) of a sphere of radius
        `R` (m; the effective radius of two spheres)."""

    @abc.abstractmethod
    def replace(self, **params) -> "AbstractTangentialLaw":
        """The same law with some parameters changed."""

    @property
    def mu(self) -> Array:
        """Coulomb's friction coefficient."""
        return self.params["mu"]

    def forces_scaled(self, factor: float) -> "AbstractTangentialLaw":
        """The law whose tangential force is `factor` times this one's in every state:
        its stiffness and damper scaled (`FORCE_PARAMETERS`), `mu` and damping ratios
        kept. With a normal force scaled alike it moves a body of mass `factor m` as this
        law moves `m` (an export's two spheres of mass `m`: `factor` 1/2)."""
        names = [k for k in self.FORCE_PARAMETERS if k in self.params]
        return self.replace(**{k: self.params[k] * factor for k in names})

    def damping_scale(self, *, m, R) -> tuple[Array, float]:
        """`(D0, power)` of the damper on the slip while sticking, `D = D0 x^power` (N s/m at
        overlap x in m) for a sphere of mass `m` (kg) and radius `R` (m): `linear_history`'s
        constant `ct`; the Mindlin laws' `2 (5/6)^0.5 beta (m 8 G* R^0.5)^0.5 x^(1/4)`."""
        return self.params.get("ct", jnp.zeros_like(self.params["mu"])), 0.0

    @property
    def parameters(self) -> dict[str, Array]:
        return dict(self.params)

    @property
    def history(self) -> str:
        return self.spec.history

    @abc.abstractmethod
    def _stiffness_scale(self, R):
        """`k0` of `k_t = k0 x^power` (SI) for a sphere of radius `R` (m)."""

    def dynamics(self, *, m, R, inertia, x_star, v_n) -> TangentialDynamics:
        """The law in the normal contact's units: a sphere of mass `m` (kg), radius `R`
        (m), moment of inertia `inertia m R^2`, the normal contact's length scale `x_star`
        (m) and normal speed `v_n` (m/s)."""
        energy = m * v_n**2
        k0 = self._stiffness_scale(R) * x_star ** (self.spec.power + 2.0) / energy
        d0, damping_power = self.damping_scale(m=m, R=R)
        return TangentialDynamics(
            mu=jnp.asarray(self.mu, dtype=float),
            k0=jnp.asarray(k0, dtype=float),
            damping=jnp.asarray(d0 * x_star ** (damping_power + 1.0) / (m * v_n), dtype=float),
            inv_inertia=jnp.asarray(1.0 / inertia, dtype=float),
            power=self.spec.power,
            history=self.spec.history,
            damping_power=damping_power,
            damper_tested=self.spec.damper_tested,
            rescaled=self.spec.rescaled,
        )

    def _refuse_unknown(self, params):
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"tangential law {self.name!r} has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )

    def __getattr__(self, item):
        params = self.__dict__.get("params")
        if params is not None and item in params:
            return params[item]
        raise AttributeError(item)


class LinearHistoryLaw(AbstractTangentialLaw):
    """Cundall & Strack's tangential spring: `F_t = -kt delta - ct u` while sticking
    (`delta' = u`, the displacement history), limited to `mu |F_n|`; built by
    `tangential_law("linear_history", kt=..., mu=..., ct=0.0)` (kt in N/m, ct in N s/m).
    While sliding the spring is held at the limit, `delta = (s mu |F_n| - ct u) / kt`, as
    LAMMPS's `linear_history` and LIGGGHTS' `tangential history` truncate it.

    **Example**: `tangential_law("linear_history", kt=1e7, mu=0.092).stiffness(1e-6, R=2.5e-3)`
    is `1e7`.
    """

    params: dict[str, Array]
    FORCE_PARAMETERS: ClassVar[tuple[str, ...]] = ("kt", "ct")

    @property
    def name(self) -> str:
        return LINEAR_HISTORY.name

    @property
    def spec(self) -> TangentialSpec:
        return LINEAR_HISTORY

    def stiffness(self, x, *, R=None):
        return self.params["kt"] + jnp.zeros_like(jnp.asarray(x, dtype=float))

    def _stiffness_scale(self, R):
        return self.params["kt"]

    def replace(self, **params):
        self._refuse_unknown(params)
        return tangential_law(self.name, **{**self.params, **params})


class MindlinLaw(AbstractTangentialLaw):
    """Mindlin's no-slip tangential stiffness `k_t = 8 G* sqrt(R x)` (the contact radius
    `a = sqrt(R x)` of Hertz), limited to `mu |F_n|` (Coulomb, no micro-slip annulus);
    built by `tangential_law("mindlin", G=..., nu=..., mu=...)` or `(..., G_star=...,
    mu=...)`, with `1/G* = (2 - nu)/G + (2 - nu2)/G2` (a rigid plane: `G2` infinite, the
    default). `"mindlin"` keeps the displacement history (`F_t = -k_t(x) delta`, LAMMPS
    `mindlin`), `"mindlin_force"` the force history (`F_t' = -k_t(x) u`, LAMMPS
    `mindlin/force`, Yade's Hertz-Mindlin); neither rescales it on unloading.
    R. D. Mindlin, J. Appl. Mech. 16 (1949) 259; Di Renzo & Di Maio, Chem. Eng. Sci. 59
    (2004) 525.

    **Example**: `tangential_law("mindlin", G=1.5e11, nu=0.23, mu=0.092)`.
    """

    name: str = eqx.field(static=True)
    params: dict[str, Array]
    FORCE_PARAMETERS: ClassVar[tuple[str, ...]] = ("G_star",)  # beta is a ratio

    @property
    def spec(self) -> TangentialSpec:
        return TANGENTIAL_LAWS[self.name]

    def stiffness(self, x, *, R):
        x = jnp.asarray(x, dtype=float)
        return 8.0 * self.params["G_star"] * safe_pow(R * x, 0.5)

    def _stiffness_scale(self, R):
        return 8.0 * self.params["G_star"] * jnp.sqrt(R)

    def damping_scale(self, *, m, R):
        scale = 8.0 * self.params["G_star"] * jnp.sqrt(R)  # k_t = scale x^0.5
        return 2.0 * jnp.sqrt(5.0 / 6.0) * self.params["beta"] * jnp.sqrt(m * scale), 0.25

    def replace(self, **params):
        self._refuse_unknown(params)
        return tangential_law(self.name, **{**self.params, **params})


_LINEAR_UNITS = {"kt": "N/m", "mu": "-", "ct": "N s/m"}
_MINDLIN_UNITS = {
    "G_star": "Pa",
    "mu": "-",
    "beta": "-",
    "G": "Pa",
    "nu": "-",
    "G2": "Pa",
    "nu2": "-",
}
_MINDLIN_REFERENCE = (
    "R. D. Mindlin, J. Appl. Mech. 16 (1949) 259; k_t = 8 G* a, a = sqrt(R x); "
    "Di Renzo & Di Maio, Chem. Eng. Sci. 59 (2004) 525"
)

LINEAR_HISTORY = TangentialSpec(
    name="linear_history",
    formula="F_t = -kt delta - ct u, delta' = u while sticking; |F_t| <= mu |F_n|",
    parameters=("kt", "mu", "ct"),
    units=_LINEAR_UNITS,
    reference="P. A. Cundall & O. D. L. Strack, Geotechnique 29 (1979) 47",
    history="displacement",
    power=0.0,
    engines="LAMMPS pair granular tangential linear_history; LIGGGHTS tangential history "
    "(hooke); Chrono SMC Hooke; MercuryDPM sliding friction",
    positive=("kt",),
    defaults={"ct": 0.0},
)
MINDLIN = TangentialSpec(
    name="mindlin",
    formula="F_t = -8 G* sqrt(R x) delta - 2 sqrt(5/6) beta sqrt(m k_t) u, delta' = u while "
    "sticking; |8 G* sqrt(R x) delta| <= mu |F_n|",
    parameters=("G_star", "mu", "beta"),
    units=_MINDLIN_UNITS,
    reference=_MINDLIN_REFERENCE,
    history="displacement",
    power=0.5,
    engines="LAMMPS pair granular tangential mindlin (no rescaling)",
    positive=("G_star",),
    defaults={"beta": 0.0},
    inputs=("G", "nu", "G2", "nu2"),
    damper_tested=False,  # LIGGGHTS' and EDEM's: Coulomb's test on the spring alone
)
MINDLIN_FORCE = dataclasses.replace(
    MINDLIN,
    name="mindlin_force",
    formula="F_t = S - 2 sqrt(5/6) beta sqrt(m k_t) u, S' = -8 G* sqrt(R x) u while "
    "sticking; |S| <= mu |F_n|",
    history="force",
    engines="LAMMPS pair granular tangential mindlin/force (no rescaling); Yade "
    "Law2_ScGeom_MindlinPhys_Mindlin (incremental shear force)",
)

MINDLIN_RESCALE = dataclasses.replace(
    MINDLIN,
    name="mindlin_rescale",
    formula="F_t = -8 G* sqrt(R x) delta - 2 sqrt(5/6) beta sqrt(m k_t) u, delta' = u + "
    "delta min(x', 0)/(2x) while sticking; |8 G* sqrt(R x) delta| <= mu |F_n|",
    rescaled=True,
    engines="LAMMPS pair granular tangential mindlin_rescale",
)
MINDLIN_RESCALE_FORCE = dataclasses.replace(
    MINDLIN_FORCE,
    name="mindlin_rescale_force",
    formula="F_t = S - 2 sqrt(5/6) beta sqrt(m k_t) u, S' = -8 G* sqrt(R x) u + S min(x', "
    "0)/(2x) while sticking; |S| <= mu |F_n|",
    rescaled=True,
    engines="LAMMPS pair granular tangential mindlin_rescale/force",
)

TANGENTIAL_LAWS: dict[str, TangentialSpec] = {
    spec.name: spec
    for spec in (LINEAR_HISTORY, MINDLIN, MINDLIN_FORCE, MINDLIN_RESCALE, MINDLIN_RESCALE_FORCE)
}
TANGENTIAL_LAW_NAMES: tuple[str, ...] = tuple(TANGENTIAL_LAWS)
_CLASSES = {
    name: LinearHistoryLaw if name == "linear_history" else MindlinLaw
    for name in TANGENTIAL_LAW_NAMES
}


def shear_modulus_star(G, nu, G2=None, nu2=0.0):
    """`G* = 1 / ((2 - nu)/G + (2 - nu2)/G2)` (Pa): Mindlin's effective shear modulus of a
    sphere (shear modulus `G` in Pa, Poisson's ratio `nu`) on a body `G2`, `nu2`, or on a
    rigid plane (`G2=None`)."""
    compliance = (2.0 - nu) / G
    if G2 is not None:
        compliance = compliance + (2.0 - nu2) / G2
    return 1.0 / compliance


# Poisson's ratio taken where a shear modulus comes without one (with a warning), as the
# engines' exports take it (`poisson=0.3`)
POISSON_DEFAULT = 0.3


def _mindlin_parameters(name, given):
    """`G_star` and `mu` from what the user gave: `G_star` itself, or `G` and `nu` (and
    `G2`, `nu2` for a second body); a modulus without its Poisson's ratio takes
    `POISSON_DEFAULT`, and says so in a warning."""
    if "G_star" in given:
        extra = sorted(set(given) & {"G", "nu", "G2", "nu2"})
        if extra:
            raise ValueError(
                f"tangential law {name!r}: give G_star or G and nu, not both "
                f"(got G_star and {', '.join(extra)})"
            )
        return {"G_star": given["G_star"]}
    if "G" not in given:
        raise ValueError(
            f"tangential law {name!r} needs G (Pa) and nu, or G_star (Pa); "
            f"got {', '.join(sorted(given)) or 'nothing'}"
        )
    check_positive(f"{name}: shear modulus G", given["G"], "Pa")
    G2 = given.get("G2")
    if G2 is not None:
        check_positive(f"{name}: shear modulus G2", G2, "Pa")
    if "nu2" in given and G2 is None:
        raise ValueError(f"tangential law {name!r}: nu2 without G2 (the second body's modulus)")
    assumed = [
        k
        for k, modulus in (("nu", "G"), ("nu2", "G2"))
        if given.get(modulus) is not None and k not in given
    ]
    if assumed:
        import warnings

        warnings.warn(
            f"tangential law {name!r}: {' and '.join(assumed)} not given, taken as "
            f"{POISSON_DEFAULT} (G* = 1 / ((2 - nu)/G + ...)); give "
            f"{' and '.join(assumed)}, or G_star, to set it",
            stacklevel=3,
        )
    nu, nu2 = given.get("nu", POISSON_DEFAULT), given.get("nu2", POISSON_DEFAULT)
    _check_poisson(name, "nu", nu)
    _check_poisson(name, "nu2", nu2)
    return {"G_star": shear_modulus_star(given["G"], nu, G2, nu2)}


def _check_poisson(name, key, value):
    if is_traced(value):
        return
    import numpy as np

    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)) or np.any(array <= -1.0) or np.any(array >= 0.5):
        raise ValueError(f"{name}: Poisson's ratio {key} must lie in (-1, 0.5), got {value}")


# friction coefficients of real dry contacts: about 0.05 (PTFE) to 1.5 (clean metals, rubber)
LIKELY_MU = 2.0


def _warn_unlikely_friction(mu):
    """A warning where a concrete `mu` is above `LIKELY_MU` (a slip of a digit or a unit):
    such a contact sticks wherever it can, and a fit from it fixes no friction."""
    if is_traced(mu) or np.ndim(mu) != 0:
        return
    if float(mu) > LIKELY_MU:
        warnings.warn(
            f"mu = {float(mu):g} is far above the friction of real dry contacts (about 0.05 "
            f"to 1.5): such a contact sticks wherever it can; check the value",
            stacklevel=3,
        )


def tangential_law(name: str, **params) -> AbstractTangentialLaw:
    """Build the tangential law `name` of `TANGENTIAL_LAW_NAMES` (SI units).

    - `"linear_history"`: `kt` (N/m, > 0), `mu` (>= 0), `ct` (N s/m, >= 0, default 0).
    - `"mindlin"`, `"mindlin_force"`: `mu` and either `G_star` (Pa) or the sphere's shear
      modulus `G` (Pa) and Poisson's ratio `nu` (and `G2`, `nu2` of a second body; a rigid
      plane without them; a Poisson's ratio not given is taken as 0.3, with a warning);
      `beta` (>= 0, default 0), the damper of EDEM's and LIGGGHTS' Hertz-Mindlin (module
      docstring).

    **Example**: `tangential_law("linear_history", kt=1e7, mu=0.3)`.
    """
    if name not in TANGENTIAL_LAWS:
        raise ValueError(unknown_name("tangential law", name, TANGENTIAL_LAW_NAMES))
    spec = TANGENTIAL_LAWS[name]
    unknown = sorted(set(params) - set(spec.parameters) - set(spec.inputs))
    if unknown:
        accepted = ", ".join(spec.parameters + spec.inputs)
        raise ValueError(
            f"tangential law {name!r} has no parameter {', '.join(unknown)}; it takes {accepted}"
        )
    for key, value in params.items():
        if isinstance(value, (str, bytes)) or value is None:
            raise TypeError(f"parameter {key} must be a number or an array, got {value!r}")
    given = {**spec.defaults, **params}
    if "mu" not in given:
        raise ValueError(f"tangential law {name!r} needs mu, the friction coefficient (>= 0)")
    if spec.power == 0.5:
        values = {**_mindlin_parameters(name, given), "mu": given["mu"], "beta": given["beta"]}
    else:
        missing = [k for k in spec.parameters if k not in given]
        if missing:
            raise ValueError(
                f"tangential law {name!r} needs {', '.join(missing)}; "
                f"it takes {', '.join(spec.parameters)}"
            )
        values = {k: given[k] for k in spec.parameters}
    checked = {}
    for key, value in values.items():
        unit = spec.units.get(key, "")
        unit = "" if unit == "-" else unit
        if key in spec.positive:
            checked[key] = check_positive(f"{name}: {key}", value, unit)
        else:
            checked[key] = check_nonnegative(f"{name}: {key}", value, unit)
    _warn_unlikely_friction(checked["mu"])
    arrays = {k: jnp.asarray(v, dtype=float) for k, v in checked.items()}
    cls = _CLASSES[name]
    return cls(arrays) if cls is LinearHistoryLaw else cls(name, arrays)
