"""How the library compiles the programs that run for milliseconds: a fit's residuals and
Jacobian on the universal curves or a closed form, its start, its record, and
`fit_oblique`'s one program.

XLA's CPU compiler without its fusion emitters (`xla_cpu_use_fusion_emitters=False`, the
LLVM IR emitters before them) compiles these programs about a third faster and runs them
as fast (measured, one process each on 2 cores, benchmarks/fit_first_calls.md: a fit of
`bingham` 7.8 -> 5.3 CPU s, `hertz_rate` 2.0 -> 1.4, `bingham_modified`'s two-group table
12.5 -> 9.8, `compare_laws` over the seed paper's laws 51 -> 33; `fit_oblique`'s program
14.2 -> 9.9). Other integrated solves keep XLA's default: they gain less (a user's law's
`calibrate` 14.0 -> 11.5 CPU s), and the other rounding, with
`--xla_backend_optimization_level=0` (the test suite's setting), showed restitution's
start to be rounding-sensitive (an over-damped Kelvin-Voigt impact, b 25x critical,
captured at maximum compression: `phases._TURN_NOISE` fixed it). The options travel with
one top-level program (`jax.jit`'s `compiler_options`, refused on a nested `jit`), never
the process's `XLA_FLAGS`; other backends ignore an `xla_cpu_` option.

A fit's programs on a closed form or the curves (`brief=True`: each call runs for well
under a millisecond, a fit makes tens) also skip LLVM's optimisation passes
(`xla_backend_optimization_level=0`, the test suite's setting): measured (scratch), a
Bingham impact's Jacobian at 6 speeds compiles in 2.5 s instead of 3.6 and runs in 360
us instead of 200, and a first `compare_laws` over the seed paper's laws on 2 workers
took 17.0-20.1 s instead of 21.2-23.4 (3 runs each), with the same fits;
benchmarks/compare_laws_split.md has it with the two-group table's change: 30.1 -> 17.6 s.
`fit_oblique`'s program, which runs its grid of starts, keeps them: without, its second
call took 23.5 s instead of 8.9 and its first no less.
"""

import functools
import threading

from ._stored import stored_jit

QUICK_COMPILE = {"xla_cpu_use_fusion_emitters": False}
# and for a program whose calls are brief: no LLVM optimisation passes
BRIEF_COMPILE = {**QUICK_COMPILE, "xla_backend_optimization_level": 0}
# and for one that runs for seconds (`fit_oblique`'s, over its grid of starts): XLA's own
# default level (3) stated, so that `XLA_FLAGS` lowering it for every program (the test
# suite's level 0) does not slow it: under that flag a Chung & Ooi fit took 71 / 58 s (first
# and second call) against 37 / 15 s without it, and now takes 33 / 14 s with the same digits
OPTIMISED_COMPILE = {**QUICK_COMPILE, "xla_backend_optimization_level": 3}


@functools.cache
def quick_options(brief: bool = False, optimised: bool = False) -> dict:
    """`QUICK_COMPILE` (with `brief`, `BRIEF_COMPILE`; with `optimised`,
    `OPTIMISED_COMPILE`) where this JAX's XLA takes it (tried once on a one-line program),
    else `{}`: a version of XLA without the options compiles at its defaults, not fails."""
    import jax

    if brief and optimised:
        raise ValueError("a program is compiled brief or optimised, not both")
    options = BRIEF_COMPILE if brief else OPTIMISED_COMPILE if optimised else QUICK_COMPILE
    try:
        jax.jit(lambda x: x + 1, compiler_options=options).lower(1.0).compile()
    except Exception:  # an unknown option: XLA's own error type varies by version
        return {}
    return options


def quick_jit(fun, *, brief: bool = False, optimised: bool = False):
    """`eqx.filter_jit(fun)` compiled with `quick_options(brief, optimised)`, for a
    top-level program that runs for milliseconds (`brief`: well under one; `optimised`: a
    program called for seconds), where compiling is the wait;
    kept on disk as traced where JAX's persistent cache is on (`_stored`). Made at the
    first call, so that importing the library compiles nothing."""
    lock, made = threading.Lock(), []

    @functools.wraps(fun)
    def call(*args, **kwargs):
        if not made:
            with lock:
                if not made:
                    made.append(stored_jit(fun, compiler_options=quick_options(brief, optimised)))
        return made[0](*args, **kwargs)

    return call


def solve_jit(fun):
    """`stored_jit(fun)` for a solve that runs for milliseconds when called on its own (an
    eager `impact`, `bounce` or `oblique_impact`): such a call compiles with
    `quick_options()`; inside a transform or a `jit` the outer program's options hold.
    Measured on the command line, cold, one run each (benchmarks/answer_times.md):
    `simulate` 2.7 -> 2.1 s, `export lammps --wall` 9.1 -> 6.2 s."""
    return stored_jit(fun, eager_options=quick_options)
