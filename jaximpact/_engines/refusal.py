"""An export its engine cannot realise at the given step: refused (`UnrealisedExport`) or,
with `strict=False`, warned (`UnrealisedWarning`)."""

from . import _stepping
from .base import Design


class UnrealisedExport(ValueError):
    """A one-line ValueError: `engine` cannot realise the target at `step` (s) for `reason`;
    `working` (s): a step that does (0.0: a continuous plant; None: none found);
    `continuous`: the engine has a continuous plant; `T` (s): to tell steps as T/n."""

    def __init__(
        self, engine: str, step, reason: str, working, *, continuous: bool = False, T=None
    ):
        self.engine, self.step, self.reason, self.working = engine, step, reason, working
        self.continuous, self.T = continuous, T
        super().__init__(self.message("strict=False"))

    def message(self, option: str, *, exported: bool = False) -> str:
        """The refusal, ending with how to export anyway (`option`: `"strict=False"`,
        `"--no-strict"`), or with `exported` the warning of an export made so."""
        if self.working is None:
            fix = f"no time step down to T/{_stepping.MAX_STEPS} realises it"
        elif self.working == 0.0:
            fix = "use time_step = 0 (its continuous plant)"
        else:
            fix = f"use a time step of {self.working:.3g} s or less"
            if self.T:
                fix += f" ({_stepping.per_contact(self.working, self.T)})"
            if self.continuous:
                fix += " (or time_step = 0, its continuous plant)"
        if exported:
            tail = f"; exported anyway ({option})"
        else:
            tail = f", or pass {option} to export it anyway"
        return (
            f"{self.engine} cannot realise the target at time step "
            f"{_stepping.describe_step(self.step, self.T)}: {self.reason}; {fix}{tail}"
        )


class UnrealisedWarning(UserWarning):
    """`export(strict=False)`'s warning, from the `UnrealisedExport` it would have raised
    (kept as `.refusal`) or from a text."""

    def __init__(self, refusal):
        self.refusal = refusal if isinstance(refusal, UnrealisedExport) else None
        text = refusal if self.refusal is None else refusal.message("strict=False", exported=True)
        super().__init__(text)


def unrealised(out: Design, target_e: float, target_T) -> str | None:
    """Why the design `out` of an engine does not realise `target_e`, `target_T` (s)."""
    h = out.timestep
    steps = target_T / h if (h and target_T is not None) else None
    return _stepping.unrealised(
        out.e,
        out.T,
        target_e=target_e,
        target_T=target_T,
        steps_per_contact=steps,
        parameters=out.parameters,
    )


def working_step(normal, target_e: float, target_T, scene, options: dict):
    """A step (s) at which `normal` realises the target in `scene`: its recommended one, or
    for a continuous plant the first of T/50, T/100, ... T/51200 that does (else 0.0);
    None where none does."""
    try:
        out = normal.design(target_e, target_T, scene, timestep=None, **options)
    except ValueError:
        return None
    if out.target_T is not None:
        target_T = out.target_T
    if out.timestep and unrealised(out, target_e, target_T) is None:
        return float(out.timestep)
    if out.timestep == 0.0 and target_T is not None:  # a continuous plant: 0 or a step
        steps = 50
        while steps <= 51200:
            h = _stepping.nice_down(target_T / steps)
            try:
                out = normal.design(target_e, target_T, scene, timestep=h, **options)
            except ValueError:
                return 0.0
            near = abs(out.e / target_e - 1) <= 0.005 and abs(out.T / target_T - 1) <= 0.005
            if near and unrealised(out, target_e, target_T) is None:
                return h
            steps *= 2
        return 0.0
    return None
