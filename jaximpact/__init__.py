"""jaximpact: impact force laws, integrated exactly and differentiably, and fitted to data.

The public names below load their module on first use (PEP 562), so that `import jaximpact`
costs little and a call pays only for what it needs: an impact read off the universal
curves never imports diffrax or optimistix, and nothing imports matplotlib before a plot.
Neither importing the package nor reading a name changes JAX's configuration or the
environment: float64 and the persistent compilation cache are the command line's settings
(`_cli.main`) and a Python user's choice (`jax.config`, `enable_cache()`).
"""

import importlib as _importlib

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
    # the process: JAX's compilation cache, progress meters
    "enable_cache": "_cache",
    "AbstractMeter": "_progress",
    "NoMeter": "_progress",
    "TextMeter": "_progress",
    "TqdmMeter": "_progress",
    # one impact
    "ImpactResult": "_solve.results",
    "ImpactOptions": "_solve.options",
    "SolveOptions": "_solve.options",
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
    "compare_laws": "_posterior.evidence",  # by="aic": _fit.model_choice's; "evidence"
    "clean_impact_times": "_fit.impact_times",
    "interval_restitution": "_fit.impact_times",
    "read_recording": "_fit.recordings",
    "starting_law": "_fit.model_choice",
    # many impacts
    "impact_batch": "_jobs",
    "run_batch": "_batch",
    "write_table": "_batch",
    "batch_file": "_jobs",
    "BatchFile": "_jobs",
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
        "yield_overlap": "_engines.materials",
        "yield_pressure": "_engines.materials",
        "work_of_adhesion": "_engines.materials",
        "effective_mass": "_engines",
        "effective_radius": "_engines",
        "export": "_engines",
        "Export": "_engines",
    }
)
# oblique impacts: tangential laws, oblique_impact, fit_oblique, video tracks (issue 27)
_PUBLIC.update(
    dict.fromkeys(
        (
            "tangential_law",
            "TANGENTIAL_LAW_NAMES",
            "TANGENTIAL_LAWS",
            "AbstractTangentialLaw",
            "LinearHistoryLaw",
            "MindlinLaw",
            "oblique_impact",
            "oblique_impact_batch",
            "ObliqueResult",
            "rigid_oblique",
            "incidence",
            "two_spheres",
            "fit_oblique",
            "ObliqueFit",
            "track_rebounds",
            "TrackRebounds",
        ),
        "_oblique",
    )
)
# uncertainty: posteriors of fits, their bands, the next measurement (issue 37)
_PUBLIC.update(
    posterior="_posterior.posterior",
    Posterior="_posterior.result",
    next_measurement="_posterior.next_measurement",
    NextMeasurement="_posterior.next_measurement",
)
_SUBMODULES = ("closed_forms",)

__all__ = sorted([*_PUBLIC, *_SUBMODULES])


def __getattr__(name):
    if name == "__version__":  # importlib.metadata, read on first use: the command line's
        # Ctrl-C handling is installed right after this package loads (`_cli`)
        from ._version import __version__ as value
    elif name in _PUBLIC:
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
    return sorted({*__all__, *dunder, "__version__"})
