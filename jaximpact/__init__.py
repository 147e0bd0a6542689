"""jaximpact: impact force laws, integrated exactly and differentiably, and fitted to data.

The public names below load their module on first use (PEP 562), so that `import jaximpact`
costs little and a call pays only for what it needs: an impact read off the universal
curves never imports diffrax or optimistix, and nothing imports matplotlib before a plot.
The first use also turns on JAX's persistent compilation cache (`_cache`; opt out with
`JAXIMPACT_CACHE_DIR=`), so a second process reuses the compiled programs.
"""

import importlib as _importlib
import os as _os
import sys as _sys

if _os.path.basename(_sys.argv[0]) == "jaximpact":
    # the command line: XLA's CPU compiler logs harmless "algebraic simplifier ... circular"
    # notes at error level for diffrax's loops; the level is read when jax loads, so it is
    # set here, before anything imports jax, and only for the `jaximpact` console script
    _os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
    # equinox's run-time checks inside the compiled fits (lineax's, in the implicit
    # derivative of diffrax's event times) are host callbacks, and JAX does not store a
    # program with host callbacks in its persistent cache; as NaN instead (which the fits
    # already report as a failed solve) the second `jaximpact calibrate` skips XLA's
    # compilation: 14 s -> 8 s (benchmarks/first_calls.md). Inputs are checked before.
    _os.environ.setdefault("EQX_ON_ERROR", "nan")
    # Ctrl-C or SIGTERM while the command line starts (importing JAX takes a second):
    # nothing is written yet, so stop at once with one line; `main` installs the handlers
    # that stop a running command cleanly (`_interrupt`)
    from ._interrupt import stop_at_once as _stop_at_once

    _stop_at_once()

# public name -> the private module that defines it, grouped as the package is layered:
# force laws, one impact, one drop, fitting, many impacts, studies, figures, the paper
_PUBLIC = {
    # force laws
    "LAW_NAMES": "_laws",
    "LAWS": "_laws",
    "AbstractLaw": "_laws",
    "CustomLaw": "_laws",
    "Law": "_laws",
    "custom_law": "_laws",
    "law": "_laws",
    "safe_pow": "_powers",
    # one impact
    "ImpactResult": "_solve.results",
    "impact": "_solve.impact",
    "Status": "_status",
    # one drop
    "BounceResult": "_solve.bounce",
    "bounce": "_solve.bounce",
    "euler_bounce": "_solve.euler",
    # fitting
    "Fit": "_fit.calibrate",
    "calibrate": "_fit.calibrate",
    "BounceFit": "_fit.bounce_fit",
    "fit_bounces": "_fit.fit_bounces",
    "compare_laws": "_fit.model_choice",
    "clean_impact_times": "_fit.impact_times",
    "interval_restitution": "_fit.impact_times",
    "read_recording": "_fit.recordings",
    "starting_law": "_fit.model_choice",
    # many impacts
    "impact_batch": "_batch",
    "run_batch": "_batch",
    "write_table": "_batch",
    "batch_file": "_batch.files",
    "BatchFile": "_batch.files",
    # studies
    "bumper_design": "_studies.bumper",
    "drop_design": "_studies.drop",
    "propagate_uncertainty": "_studies.uncertainty",
    "sensitivity_map": "_studies.sensitivity",
    "plot_sensitivity": "_studies.sensitivity",
    "plot_map": "_studies.maps",
    "restitution_map": "_studies.maps",
    # figures, the seed paper
    "plot_impact": "_plotting",
    "reproduce_paper": "_paper.reproduce",
}
# engines: material inputs and exports to MuJoCo, Drake, LAMMPS (issue 14)
_PUBLIC.update(
    {
        "hertz_stiffness": "_engines",
        "effective_mass": "_engines",
        "effective_radius": "_engines",
        "export": "_engines",
        "Export": "_engines",
    }
)
_SUBMODULES = ("closed_forms",)

__all__ = sorted([*_PUBLIC, *_SUBMODULES])


def __getattr__(name):
    if name in _PUBLIC or name in _SUBMODULES:
        from ._cache import enable_persistent_cache

        enable_persistent_cache()  # compiled programs kept between processes (_cache)
    if name in _PUBLIC:
        value = getattr(_importlib.import_module(f".{_PUBLIC[name]}", __name__), name)
    elif name in _SUBMODULES:
        value = _importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__():
    """The public names (`__all__`) and the module's dunder attributes: not the modules
    it imports for itself, nor the private subpackages that loading a name brings in."""
    dunder = [k for k in globals() if k.startswith("__") and k.endswith("__")]
    return sorted({*__all__, *dunder})


from ._version import __version__ as __version__  # noqa: E402
