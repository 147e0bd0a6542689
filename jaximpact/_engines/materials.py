"""Material inputs: Hertz (1882; Johnson, *Contact Mechanics* 1985, section 4.2), two elastic
spheres pressed together by `x` (m) repel with `F = c x^1.5`, `c = (4/3) E* sqrt(R*)`,
`1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`, `1/R* = 1/R1 + 1/R2` (a flat: `R2 = inf`)."""

import math
import sys

__all__ = [
    "effective_mass",
    "effective_radius",
    "effective_modulus",
    "hertz_stiffness",
    "yield_overlap",
    "work_of_adhesion",
]


def check_positive(name: str, value, unit: str, *, infinite_ok: bool = False) -> float:
    """`value` as a float > 0 (finite unless `infinite_ok`); a one-line ValueError if not."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in {unit}, got {value!r}") from None
    if math.isnan(number) or number <= 0 or (math.isinf(number) and not infinite_ok):
        bound = "> 0 (inf allowed)" if infinite_ok else "a finite number > 0"
        raise ValueError(f"{name} must be {bound} {unit}, got {value!r}")
    return number


def check_poisson(name: str, value) -> float:
    """`value` as a Poisson ratio, which must lie in (-1, 0.5); a one-line ValueError if not."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} (Poisson's ratio) must be a number, got {value!r}") from None
    if not -1.0 < number < 0.5:
        raise ValueError(f"{name} (Poisson's ratio) must lie in (-1, 0.5), got {value!r}")
    return number


def effective_mass(m1, m2=math.inf) -> float:
    """The reduced mass `m1 m2 / (m1 + m2)` (kg) of masses `m1`, `m2` (kg; `m2 = inf`, the
    default: a fixed body). **Example**: `effective_mass(0.1, 0.3)` is `0.075`."""
    m1 = check_positive("m1", m1, "kg", infinite_ok=True)
    m2 = check_positive("m2", m2, "kg", infinite_ok=True)
    if math.isinf(m1) and math.isinf(m2):
        raise ValueError("effective_mass: at least one of m1, m2 must be finite (kg)")
    if math.isinf(m2):
        return m1
    if math.isinf(m1):
        return m2
    return m1 * m2 / (m1 + m2)


def effective_radius(R1, R2=math.inf) -> float:
    """The effective radius `R* = R1 R2 / (R1 + R2)` (m) of spheres of radii `R1`, `R2` (m;
    `R2 = inf`, the default: a flat). **Example**: `effective_radius(0.01, 0.01)` is 0.005."""
    R1 = check_positive("R1", R1, "m", infinite_ok=True)
    R2 = check_positive("R2", R2, "m", infinite_ok=True)
    if math.isinf(R1) and math.isinf(R2):
        raise ValueError(
            "effective_radius: two flats have no Hertz contact; give a finite radius (m)"
        )
    if math.isinf(R2):
        return R1
    if math.isinf(R1):
        return R2
    return _representable("R*", R1 / (1.0 + R1 / R2), "m")


def effective_modulus(E, nu, E2=None, nu2=None) -> float:
    """The contact modulus `E*` (Pa), `1/E* = (1 - nu^2)/E + (1 - nu2^2)/E2`; `E2`, `nu2`
    default to `E`, `nu`; `E2 = inf`: a rigid counterpart."""
    E = check_positive("E", E, "Pa")
    nu = check_poisson("nu", nu)
    E2 = E if E2 is None else check_positive("E2", E2, "Pa", infinite_ok=True)
    nu2 = nu if nu2 is None else check_poisson("nu2", nu2)
    # p / (1 + p/q) with p = E/(1 - nu^2), q = E2/(1 - nu2^2): no sum of compliances to
    # overflow, and (1 - nu)(1 + nu) keeps its digits as nu nears -1
    p = E / ((1.0 - nu) * (1.0 + nu))
    q = math.inf if math.isinf(E2) else E2 / ((1.0 - nu2) * (1.0 + nu2))
    return _representable("E*", p / (1.0 + p / q), "Pa")


def hertz_stiffness(E, nu, R, E2=None, nu2=None, R2=None) -> float:
    """The Hertz constant `c = (4/3) E* sqrt(R*)` (N/m^1.5) of `F = c x^1.5` (Johnson 1985,
    eq. 4.23): a sphere of `E` (Pa), `nu` (in (-1, 0.5)), `R` (m) on a second body of `E2`,
    `nu2` (default the same material; `E2=math.inf`: rigid) and radius `R2` (m; None: a flat).

    Use it to fix the stiffness and fit only the damping, e.g.
    `calibrate(law("hertz_rate", c=hertz_stiffness(E=2e11, nu=0.3, R=0.01), b1=100.0),
    m=..., v0=..., e=..., free=("b1",))`.

    **Example**: `hertz_stiffness(E=2e11, nu=0.3, R=0.01)` (steel ball on a steel plate) is
    about `1.465e10` N/m^1.5.
    """
    R = check_positive("R", R, "m")
    R_star = R if R2 is None else effective_radius(R, R2)
    return _representable(
        "c", 4.0 / 3.0 * effective_modulus(E, nu, E2, nu2) * math.sqrt(R_star), "N/m^1.5"
    )


def yield_overlap(E, nu, R, *, p_y=None, Y=None, E2=None, nu2=None, R2=None) -> float:
    """The yield overlap `x_y = R* (pi p_y / (2 E*))^2` (m) of `law("thornton", ...)`, where
    the Hertz contact's mean pressure reaches the limiting pressure `p_y` (Pa; or the yield
    stress `Y`, `p_y = 1.6 Y`: Johnson 1985, section 6.2) (Thornton 1997); the bodies as in
    `hertz_stiffness`. **Example**: a steel ball (R = 5 mm) on a rigid flat,
    `yield_overlap(E=2.1e11, nu=0.3, R=5e-3, Y=1e9, E2=math.inf)`, about 0.36 µm."""
    if (p_y is None) == (Y is None):
        raise ValueError("give the limiting contact pressure p_y (Pa) or the yield stress Y (Pa)")
    p_y = 1.6 * check_positive("Y", Y, "Pa") if p_y is None else check_positive("p_y", p_y, "Pa")
    R = check_positive("R", R, "m")
    R_star = R if R2 is None else effective_radius(R, R2)
    E_star = effective_modulus(E, nu, E2, nu2)
    return _representable("x_y", R_star * (math.pi * p_y / (2.0 * E_star)) ** 2, "m")


def yield_pressure(x_y, E, nu, R, *, E2=None, nu2=None, R2=None) -> float:
    """The limiting pressure `p_y = (2 E* / pi) (x_y / R*)^0.5` (Pa) of a yield overlap `x_y`
    (m), `yield_overlap`'s inverse (`Y = p_y / 1.6`; a standard error `s` of `x_y` gives
    `p_y s / (2 x_y)`); the bodies as in `hertz_stiffness`. **Example**:
    `yield_pressure(fit.params["x_y"], E=2.1e11, nu=0.3, R=5e-3, E2=math.inf)`."""
    x_y = check_positive("x_y", x_y, "m")
    R = check_positive("R", R, "m")
    R_star = R if R2 is None else effective_radius(R, R2)
    E_star = effective_modulus(E, nu, E2, nu2)
    return _representable("p_y", 2.0 * E_star / math.pi * math.sqrt(x_y / R_star), "Pa")


def work_of_adhesion(gamma, gamma2=None, gamma12=0.0) -> float:
    """The work of adhesion `w = gamma + gamma2 - gamma12` (J/m^2, Dupre) of `law("jkr", ...)`
    from surface energies (J/m^2; `gamma2` defaults to `gamma`, `gamma12` to 0). A pull-off
    force written `3 pi Gamma R` uses `Gamma = w / 2`. **Example**: `work_of_adhesion(0.2)`
    is 0.4 J/m^2."""
    gamma = check_positive("gamma", gamma, "J/m^2")
    gamma2 = gamma if gamma2 is None else check_positive("gamma2", gamma2, "J/m^2")
    w = gamma + gamma2 - float(gamma12)
    if not w > 0:
        raise ValueError(f"the work of adhesion gamma + gamma2 - gamma12 must be > 0, got {w:g}")
    return w


PLAUSIBLE_MODULUS = (1e5, 1e12)  # Pa: a soft gel or foam to diamond (1.2e12)
SHEAR_FACTOR = 100.0  # how far a shear modulus may lie from E / (2 (1 + nu)) unwarned
# kg/m^3: a thin hollow ball (a ping-pong ball: 80) to osmium (22,590); mm given as m moves
# it by 1e-9, g given as kg by 1e3
PLAUSIBLE_DENSITY = (1.0, 3e4)


def warn_sphere_density(m, R) -> None:
    """A warning where a sphere of mass `m` (kg) and radius `R` (m) has a mean density
    outside `PLAUSIBLE_DENSITY` (a unit likely wrong)."""
    import warnings

    if m is None or R is None or not (math.isfinite(m) and math.isfinite(R) and m > 0 and R > 0):
        return
    density = m / (4.0 / 3.0 * math.pi * R**3)
    low, high = PLAUSIBLE_DENSITY
    if not low <= density <= high:
        warnings.warn(
            f"a sphere of --mass {m:g} kg and --radius {R:g} m has a mean density of "
            f"{density:.3g} kg/m^3, outside {low:g} to {high:g} (a ping-pong ball's is 80, "
            "steel's 7800): check the units (--mass in kg, --radius in m)",
            stacklevel=2,
        )


def hertz_constant(law, v0: float) -> float | None:
    """The Hertz constant `c` (N/m^1.5) of `law`'s elastic force at `v0` (m/s), or None
    where it is not `c x^1.5`."""
    coefficients = law.coefficients(v0)
    if coefficients is not None:
        c, n = float(coefficients[0]), float(coefficients[1])
        return c if n == 1.5 else None
    if law.spec is not None and law.spec.units.get("c") == "N/m^1.5":
        return float(law.params["c"])
    return None


def modulus_warnings(c, tangential, *, radius: float, poisson: float, two_spheres: bool) -> list:
    """An export's sanity lines: where the Hertz constant `c` (N/m^1.5) with `radius` (m)
    implies a Young's modulus outside `PLAUSIBLE_MODULUS` (`c = 4/3 E* sqrt(R*)`, `R* = R/2`
    for `two_spheres` else `R`, `E* = E / (2 (1 - nu^2))` of one material), and where the
    `tangential` law's shear modulus (its Pa parameters) lies more than `SHEAR_FACTOR` from
    the material's, `G*/E* = (1 - nu) / (2 (2 - nu))` (`G = E / (2 (1 + nu))`)."""
    if c is None or not (c > 0 and math.isfinite(c)):
        return []
    R_star = radius / 2.0 if two_spheres else radius
    E_star = 0.75 * c / math.sqrt(R_star)
    E = E_star * 2.0 * (1.0 - poisson) * (1.0 + poisson)
    low, high = PLAUSIBLE_MODULUS
    out = []
    if not low <= E <= high:
        out.append(
            f"the contact's Hertz constant c = {c:.4g} N/m^1.5 with radius {radius:g} m "
            f"implies a Young's modulus E = {E:.3g} Pa (c = 4/3 E* sqrt(R*), E* = E/(2 (1 - "
            f"nu^2)), R* = {R_star:g} m, nu = {poisson:g}), outside what materials have "
            f"({low:g} Pa, a soft gel, to {high:g} Pa, diamond): check the law's units, m, v0 "
            "and radius"
        )
    shear = (
        []
        if tangential is None
        else [
            (key, float(tangential.params[key]))
            for key, unit in tangential.spec.units.items()
            if unit == "Pa" and key in tangential.params
        ]
    )
    expected = E_star * (1.0 - poisson) / (2.0 * (2.0 - poisson))
    for name, G_star in shear:
        ratio = G_star / expected
        if G_star > 0 and not 1.0 / SHEAR_FACTOR <= ratio <= SHEAR_FACTOR:
            G = E / (2.0 * (1.0 + poisson))
            out.append(
                f"the tangential law's {name} = {G_star:.4g} Pa is {ratio:.3g} times the "
                f"{expected:.3g} Pa of the normal contact's material (E = {E:.3g} Pa, G = E/(2 "
                f"(1 + nu)) = {G:.3g} Pa, nu = {poisson:g}; G*/E* = (1 - nu)/(2 (2 - nu))): the "
                f"two laws are not of one material (more than a factor {SHEAR_FACTOR:g} "
                "apart); check both"
            )
    return out


def _representable(name: str, value: float, unit: str) -> float:
    """`value` where float64 holds it (finite, normal), else a one-line ValueError."""
    if not (math.isfinite(value) and value >= sys.float_info.min):
        raise ValueError(
            f"{name} = {value:g} {unit}: float64 cannot hold it for these inputs; are they in "
            "SI units (E in Pa, R in m)?"
        )
    return value


def check_restitution(e, name: str = "e") -> float:
    """`e` as a float in (0, 1]; a one-line ValueError otherwise."""
    try:
        number = float(e)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number in (0, 1], got {e!r}") from None
    if not (0.0 < number <= 1.0):
        raise ValueError(f"{name} (restitution) must lie in (0, 1], got {e!r}")
    return number
