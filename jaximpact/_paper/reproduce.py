"""The seed paper reproduced and corrected: Polukoshko, Viba, Kononova & Sokolova, "Rigid body
impact models partially considering deformation", Proc. Estonian Acad. Sci. Eng. 13 (2007).

Every figure with numbers behind it is recomputed by `reproduce_paper(out_dir)`:

- Figs. 1 and 7: `e` and `T` over `(b, c)` for Kelvin-Voigt and Maxwell (`restitution_map`),
  under both separation criteria (the paper's Kelvin-Voigt formulas mix them: its `T`, eq. 5,
  is the force criterion's, its `e` the penetration criterion's).
- Figs. 2-6, 8-11: one impact (`m = 1 kg`, `v0 = 2.5 m/s`), the force and the velocity
  against the penetration, converged (`impact`) beside the paper's explicit Euler at 2e-5 s.
- Figs. 13-21 (section 7): a 1 kg ball dropped from 0.6 m (`bounce`) beside the same Euler.

and `table.md` lists, for every parameter set, the printed `e`, the `e` of the paper's Euler
scheme at its step (as printed, with the force lagging one step, and textbook Euler), and the
converged `e` and `T` under each separation criterion, naming the one nearest to the print.
`hunt_crossley_variants.md` gives the restitution each published Hunt-Crossley damping
formula really yields against the one it was asked for.
"""

import concurrent.futures
import os
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from .._files import write_text
from .._progress import AbstractMeter, metered
from .cases import (
    CRITERIA,
    DROP_DURATION,
    DROP_HEIGHT,
    LOOPS,
    MAPS,
    SCHEMES,
    V0,
    M,
    PaperCase,
    select_cases,
)
from .figures import plot_bounce, plot_loop, plot_maps
from .tables import hunt_crossley_variants_markdown, table_markdown


def _euler_impact(law, scheme: str):
    """The paper's Euler scheme for one impact: from first touch at `V0`, no gravity."""
    from .._solve.euler import euler_bounce

    return euler_bounce(law, m=M, h0=0.0, g=0.0, v_drop=V0, t_end=0.03, scheme=scheme)


def _loop_row(case: PaperCase, with_history: bool) -> dict:
    """Printed, Euler and converged `e` and `T` of one single-impact case, and the histories
    for its figure (the converged one only `with_history`)."""
    from .._laws import law as make_law
    from .._solve.impact import impact

    law = make_law(case.law, **case.params)
    row = dict(figure=case.figure, law=case.law, params=case.params, printed=case.printed)
    row["note"] = case.note
    histories = {}
    for scheme in SCHEMES:
        euler = _euler_impact(law, scheme)
        row[f"e_{scheme}"], row[f"T_{scheme}"] = float(euler.e[0]), float(euler.T[0])
        histories[scheme] = euler
    for criterion in CRITERIA:
        if criterion == "force" and with_history:
            # one solve for e, T and the figure's histories: a grid past the Euler contact,
            # which lasts longer than the converged one under the force criterion
            ts = np.linspace(0.0, 1.05 * max(row["T_paper"], row["T_euler"]), 500)
            result = impact(law, m=M, v0=V0, ts=ts)
            histories["force"] = result
        else:
            result = impact(law, m=M, v0=V0, separation=criterion)
        row[f"e_{criterion}"], row[f"T_{criterion}"] = float(result.e), float(result.T)
        row[f"status_{criterion}"] = result.status_name
    row["nearest"] = _nearest(row)
    return row, law, histories


def _nearest(row) -> str | None:
    """Which computed `e` is nearest to the printed one."""
    if row["printed"] is None:
        return None
    keys = [f"e_{k}" for k in (*SCHEMES, *CRITERIA)]
    return min(keys, key=lambda key: abs(row[key] - row["printed"]))[2:]


def _bounce_row(case: PaperCase) -> tuple[dict, dict]:
    """First-contact `e` and `T` of a section-7 drop: printed, Euler, converged."""
    from .._laws import law as make_law
    from .._solve.bounce import bounce
    from .._solve.euler import euler_bounce

    law = make_law(case.law, **case.params)
    row = dict(figure=case.figure, law=case.law, params=case.params, printed=case.printed)
    row["note"] = "first contact of a drop from 0.6 m"
    drops = {}
    for scheme in SCHEMES:
        euler = euler_bounce(law, m=M, h0=DROP_HEIGHT, t_end=DROP_DURATION, scheme=scheme)
        row[f"e_{scheme}"], row[f"T_{scheme}"] = float(euler.e[0]), float(euler.T[0])
        row[f"e_{scheme}_later"] = [float(e) for e in euler.e[1:4]]
        drops[scheme] = euler
    for criterion in CRITERIA:
        drop = bounce(law, m=M, h0=DROP_HEIGHT, t_end=DROP_DURATION, separation=criterion)
        row[f"e_{criterion}"], row[f"T_{criterion}"] = float(drop.e[0]), float(drop.T[0])
        row[f"status_{criterion}"] = drop.status_name
        row[f"e_{criterion}_later"] = [float(e) for e in np.asarray(drop.e)[1:4]]
        drops[criterion] = drop
    row["nearest"] = _nearest(row)
    return row, drops


def reproduce_paper(
    out_dir, *, only=None, figures: bool = True, progress: bool | AbstractMeter = False
) -> dict:
    """Recompute the seed paper's figures and tables into the directory `out_dir`.

    Writes `fig<N>.png` for each figure (`fig1_force.png`, `fig1_penetration.png`,
    `fig3_caption.png`, `fig3_text.png`, ...; none if `figures=False`), `table.md` (printed,
    Euler and converged `e` and `T`) and `hunt_crossley_variants.md`. `only`: figure numbers
    to restrict to (e.g. `["2", "13-15"]`; the variants table is written only without it).
    Returns `{"rows": [...], "files": [...]}` (SI units). `progress`: a meter of the cases,
    as in `run_batch`.

    **Example**: `jaximpact.reproduce_paper("paper", only=["10"])["rows"][0]["e_force"]`.
    """
    cases = select_cases(only)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows, files = [], []
    tasks = len(cases) + (only is None)
    x64 = jnp.result_type(float) == jnp.float64  # JAX's config contexts are per thread

    def computed(case):
        with jax.enable_x64(x64):
            if case in LOOPS:
                return _loop_row(case, with_history=figures)
            return _bounce_row(case)

    # the cases' impacts in threads, one per core (a first run is mostly compiling, which
    # XLA does outside Python's lock); the figures drawn here, in the cases' order
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
    with metered(progress, tasks, "paper") as bar:
        try:
            futures = [None if case in MAPS else pool.submit(computed, case) for case in cases]
            _draw(cases, futures, figures, out_dir, rows, files, bar)
        finally:  # an interrupt or a failure: the cases not started are dropped
            pool.shutdown(wait=False, cancel_futures=True)
        if rows:
            path = out_dir / "table.md"
            write_text(path, table_markdown(rows))
            files.append(path)
        if only is None:
            path = out_dir / "hunt_crossley_variants.md"
            write_text(path, hunt_crossley_variants_markdown())
            files.append(path)
            bar.update(1, "Hunt-Crossley variants")
    return dict(rows=rows, files=[str(f) for f in files])


def _draw(cases, futures, figures, out_dir, rows, files, bar):
    """Each case's figures in order (the maps computed here), its row appended to `rows`
    and its files to `files`, as its entry of `futures` (`_loop_row`'s or `_bounce_row`'s
    result; None for a map) comes."""
    for case, future in zip(cases, futures, strict=True):
        if case in MAPS:
            if figures:
                files += plot_maps(case, out_dir)
        elif case in LOOPS:
            row, law, histories = future.result()
            rows.append(row)
            if figures:
                suffix = f"_{case.note.split(':')[0]}" if case.figure == "3" else ""
                path = out_dir / f"fig{case.figure}{suffix}.png"
                plot_loop(row, law, histories, path)
                files.append(path)
        else:
            row, drops = future.result()
            rows.append(row)
            if figures:
                files += plot_bounce(row, drops, out_dir)
        bar.update(1, f"fig. {case.figure}")
