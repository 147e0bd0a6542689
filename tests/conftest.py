"""Test configuration: float64 everywhere, and `tests/` importable (`reference`, `helpers`).

- XLA compiles without LLVM's optimisation passes (`--xla_backend_optimization_level=0`,
  unless `XLA_FLAGS` is already set): compiling, not running, is what the suite spends its
  time on (about a third less wall time measured). Results agree with the optimised build
  to rounding (LLVM's contraction of multiply-adds differs), so a test that compares two
  processes bit for bit gives both the same flags (test_batch.py).
- The fast suite (a run whose mark expression leaves the slow tests out, as the default
  `addopts` does) also compiles without XLA's CPU fusion emitters
  (`--xla_cpu_use_fusion_emitters=false`, as the library's quick programs compile; see
  `FAST_SUITE_FLAG`). The slow group keeps them: the gravity table's rebuild split one more
  piece under the flag (test_gravity_curves.py), and its rounding-sensitive sweeps were
  checked against the default build.
- Strict about shapes: implicit rank promotion raises (`jax_numpy_rank_promotion`), so a
  broadcast that was not meant fails here. Dtype promotion stays standard: strict promotion
  fails inside optax's L-BFGS, whose counters mix int32 and int64 under float64.
- Hypothesis draws new examples on every run here, so that the fuzz tests keep searching;
  `.ci/run` sets `HYPOTHESIS_PROFILE=ci` (`derandomize`: the same examples on every run),
  so that a landing does not depend on the draw. A failure found by chance locally becomes
  an `@example` of its test.
- JAX's persistent compilation cache on, as a user turns it on (`jaximpact.enable_cache()`;
  the library itself changes no JAX setting): compiled programs are reused between runs.
- The fast suite's budget (3 minutes on 2 cores with an empty cache): the tests in
  `SLOW_BY_COST` each compile programs that no other fast test shares (measured: 4 to 13
  CPU seconds each, 2026-11-27: the suite was 558 CPU s before, then 439 and 381 CPU s,
  3:45 and 3:17 wall, after the first two rounds); they are marked `slow` here, in one
  place, and run in the slow group (`.ci/run`). Each feature they check keeps a cheaper fast test.
- The command line's progress reports (on stderr, also when it is not a terminal) are turned
  off for the tests, which check stderr line by line; tests of the progress turn it on.
"""

import os
import sys

# the suite's own compiler flags, only where the user set none (a worker inherits them)
_OWN_FLAGS = "XLA_FLAGS" not in os.environ
os.environ.setdefault("XLA_FLAGS", "--xla_backend_optimization_level=0")
os.environ.setdefault("JAXIMPACT_PROGRESS", "off")

import jax  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

import jaximpact  # noqa: E402

settings.register_profile("ci", derandomize=True, database=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_numpy_rank_promotion", "raise")
jaximpact.enable_cache()

_TESTS = os.path.dirname(os.path.abspath(__file__))
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)


# node ids (a parametrised test: its id, or its name for every case); see the docstring
SLOW_BY_COST = (
    "tests/posterior/test_grid_reference.py::test_laplace_is_honestly_different_where_skewed",
    "tests/posterior/test_record.py::test_noise_scale_is_a_parameter_without_sigmas",
    "tests/curves/test_gravity_curves.py::test_single_impact_takes_the_table_and_matches",
    "tests/laws/test_closed_forms_linear.py::test_gradients_match_finite_differences",
    "tests/fit/test_fit_bounces.py::test_a_list_of_drops_is_fitted_drop_by_drop",
    "tests/laws/test_custom_laws.py::test_a_failed_solve_is_never_a_number",
    "tests/solve/test_gradients.py::test_forward_gradients_match_finite_differences",
    "tests/oblique/test_maw_similarity.py::test_the_impact_depends_on_the_groups_alone",
    "tests/laws/test_dmt.py::test_without_adhesion_it_is_law_14_and_with_it_law_14_under_gravity",
    "tests/laws/test_thornton.py::test_the_integrated_path_matches_the_closed_form",
    "tests/laws/test_thornton.py::test_with_gravity_it_matches_scipy",
    "tests/laws/test_closed_forms.py::test_maxwell_under_damped",
    "tests/solve/test_impact.py::test_gravity_matches_scipy[maxwell]",
    "tests/solve/test_impact.py::test_paper_sets_match_scipy[hertz_rate[fig10]-force]",
    "tests/solve/test_impact.py::test_histories[hertz_rate]",
    "tests/curves/test_similarity.py::test_capture_threshold_of_hertz_viscous_under_penetration",
    "tests/laws/test_jkr.py::test_gradients_of_the_closed_form_match_central_differences",
    "tests/laws/test_jkr.py::test_the_integrated_path_matches_the_closed_form",
    "tests/engines/test_export.py::test_engine_e_stepped_response_converges_to_the_continuous_law",
    "tests/solve/test_solve_options.py::test_bounce_takes_the_record_whole_and_asks_choose_path",
    "tests/solve/test_solve_options.py::test_the_record_under_jit_and_vmap",
    "tests/solve/test_solve_options.py::test_impact_batch_takes_the_record_whole",
    "tests/solve/test_solve_options.py::test_impact_takes_the_record_whole[integrate]",
    "tests/posterior/test_engine_band.py::test_the_band_is_the_draws_exported_one_by_one[lammps-kwargs0-12]",
    "tests/fit/test_fit_bounces.py::test_cli_fits_impact_times",
    "tests/fit/test_fit_bounces.py::test_cli_text_output",
    "tests/fit/test_fit_bounces.py::test_impact_times_that_go_backwards_are_refused",
    "tests/posterior/test_engine_band.py::test_the_band_is_the_draws_exported_one_by_one",
    "tests/posterior/test_engine_band.py::test_the_band_holds_the_posterior_of_the_law",
    "tests/batch/test_custom_law_files.py::test_batch_file_takes_a_users_law",
    # two users' laws' first compiles (8 s); a plain law's fast test compares with the table
    "tests/laws/test_custom_laws.py::test_users_laws_match_scipy_under_the_force_criterion",
    # a bounce fit and its Laplace posterior, one module fixture: about 50 CPU s
    *(
        f"tests/posterior/test_bounce_posterior.py::{name}"
        for name in (
            "test_laplace_agrees_with_the_fit",
            "test_record_text_and_dict",
            "test_bands_of_single_impacts",
            "test_bad_priors_and_unsupported_fits",
            "test_cli_fit_posterior",
        )
    ),
    "tests/solve/test_gradients.py::test_contact_time_derivative_at_zero_damping",
    "tests/fit/test_fit_bounces.py::test_cli_refuses_impact_times_going_backwards",
    "tests/laws/test_closed_forms_linear.py::test_matches_scipy",
    "tests/test_fuzz.py::test_bounce_heights_at_no_time",
    "tests/solve/test_impact.py::test_a_custom_law_that_pulls_is_said_to_be_unphysical",
    "tests/solve/test_impact.py::test_kelvin_voigt_default_is_the_closed_form",
    "tests/fit/test_calibrate.py::test_e_alone_cannot_fix_stiffness_and_damping_together",
    "tests/engines/test_export.py::test_lammps_wall_export_is_the_sphere_on_a_flat",
    "tests/batch/test_carried_columns.py::test_text_columns_are_carried_through_with_a_users_law",
    *(
        f"tests/engines/test_recorded_exports.py::test_the_export_is_as_recorded[{case}]"
        for case in (
            "mujoco targets",
            "lammps spheres",
            "lammps dmt spheres",
            "lammps jkr_viscoelastic spheres",
            "lammps dmt wall",
            "lammps jkr_viscoelastic wall",
        )
    ),
)


# measured on 2 cores, empty cache, alternated runs of the same tree: see the README's Tests
FAST_SUITE_FLAG = "--xla_cpu_use_fusion_emitters=false"


def pytest_configure(config):
    """The fast suite's extra compiler flag (module docstring), set before JAX starts its
    backend: the controller's environment is what xdist's workers start with."""
    if (
        _OWN_FLAGS
        and _selects_no_slow_test(config)
        and FAST_SUITE_FLAG not in os.environ["XLA_FLAGS"]
    ):
        os.environ["XLA_FLAGS"] += " " + FAST_SUITE_FLAG


def _selects_no_slow_test(config) -> bool:
    """Whether the run's mark expression (`-m`, or `addopts`' default) leaves out every test
    marked `slow` or `engines` (any combination of them with `very_slow`)."""
    from _pytest.mark.expression import Expression

    expression = config.getoption("markexpr") or ""
    if not expression.strip():
        return False
    compiled = Expression.compile(expression)
    kinds = ({"slow"}, {"slow", "very_slow"}, {"engines"}, {"slow", "engines"})
    return not any(
        compiled.evaluate(lambda name, _marks=marks, **_: name in _marks) for marks in kinds
    )


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    for item in items:
        name = item.nodeid.split("[")[0]
        if item.nodeid in SLOW_BY_COST or name in SLOW_BY_COST:
            item.add_marker(pytest.mark.slow)
