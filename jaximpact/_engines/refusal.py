"""An export its engine cannot realise at the given step: the refusal
(`UnrealisedExport`, a one-line ValueError that names a step that works) or, with
`strict=False`, its warning (`UnrealisedWarning`)."""

from . import _stepping
from .base import Design


class UnrealisedExport(ValueError):
    """An export its engine cannot realise at the given step (`_stepping.unrealised`): the
    `engine`, its time `step` (s), the `reason`, and `working` (s), a step that realises the
    target (0.0: Drake's continuous plant; None where none was found); `continuous`: the
    engine also has a continuous plant (time step 0); `T` (s): the target duration, by
    which the steps are also told as T/n."""

    def __init__(
        self, engine: str, step, reason: str, working, *, continuous: bool = False, T=None
    ):
        self.engine, self.step, self.reason, self.working = engine, step, reason, working
        self.continuous, self.T = continuous, T
        super().__init__(self.message("strict=False"))

    def message(self, option: str, *, exported: bool = False) -> str:
        """The one line: the refusal, ending with how to export it anyway (`option`:
        `"strict=False"` in Python, `"--no-strict"` on the command line), or with
        `exported` the warning of an export made anyway with that option."""
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
    """`export(..., strict=False)` of an export its engine cannot realise, built from the
    `refusal` it would have raised (an `UnrealisedExport`, kept as `.refusal`: its `message`
    in other words, as the command line's) or from a text (`.refusal` None)."""

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
    """A time step (s) at which the normal model `normal` realises the target in `scene`:
    its recommended step (the design without a step), or where that is a continuous plant
    (0.0), the first of T/50, T/100, ... T/51200 whose discrete plant does; None where none
    does. `options`: the design's other arguments."""
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
