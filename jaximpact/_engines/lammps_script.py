"""What LAMMPS's three exported models (`lammps`: hertz/material; `lammps_jkr`; `lammps_dmt`)
share: the script of an export's scene (`snippet`), and the effective radius of its contact
(`with_effective_radius`)."""

from .materials import check_positive


def snippet(parameters) -> str:
    """The LAMMPS commands of a design's `parameters`: units, atom style, its pair style and
    coefficients (and wall, for the drop test), `fix nve/sphere` and the time step."""
    return "\n".join(
        [
            "units si",
            "atom_style sphere",
            "comm_modify vel yes",
            parameters["pair_style"],
            parameters["pair_coeff"],
            *([parameters["fix_wall"]] if parameters.get("fix_wall") else []),
            "fix 1 all nve/sphere",
            parameters["timestep"],
        ]
    )


def with_effective_radius(parameters, radius) -> dict:
    """`parameters` with `R_eff` (m) from the spheres' `radius` (m) where not given: `R` on
    a wall (`geometry` "wall"), `R/2` between two spheres; a one-line ValueError without a
    radius."""
    if parameters.get("R_eff") is not None:
        return dict(parameters)
    wall = parameters.get("geometry", "spheres") == "wall"
    if radius is None:
        what = "sphere's" if wall else "spheres'"
        raise ValueError(f"lammps needs the {what} radius: pass radius= (m)")
    radius = check_positive("radius", radius, "m")
    return {**parameters, "R_eff": radius if wall else radius / 2.0}
