"""What `reproduce_paper` found, as `jaximpact paper` prints it (`paper_text`): one row per
figure, the restitution printed in the paper, by its explicit Euler scheme and converged
under either end of contact, the nearest of these to the printed one, and the files written."""

from .cases import COLUMNS


def paper_text(result: dict) -> str:
    """The table of `reproduce_paper`'s `result` (`rows`, `files`)."""
    lines = [
        "fig.   law                      printed  Euler(paper)  converged(force)  "
        "converged(pen.)  nearest"
    ]
    for row in result["rows"]:
        printed = "-" if row["printed"] is None else f"{row['printed']:.2f}"
        lines.append(
            f"{row['figure']:<6} {row['law']:<24} {printed:>7}  {row['e_paper']:>12.4f}  "
            f"{row['e_force']:>15.4f}  {row['e_penetration']:>15.4f}  "
            f"{COLUMNS.get(row['nearest'], '-')}"
        )
    return "\n".join([*lines, "", *(f"wrote {path}" for path in result["files"])])
