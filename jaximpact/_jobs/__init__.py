"""Tables on disk, a layer above `_batch` (arrays in, arrays out): `batch_file` reads a CSV or
Parquet file of bodies (or a script's chunks), checks every row once, computes the chunks
through `_batch` on one process or several, and joins the parts into the output (`job`:
`plan`, `check`, `compute`, `join`); `impact_batch` takes arrays to `_batch` and chunks to
a file. Imports `_batch`, `_laws` and the leaf helpers.

The names load with their module on first use (PEP 562), so that reading a law from a
file (`file_law`: `simulate`, `calibrate`, `export`) does not import the batch and diffrax."""

from .._lazy import lazy_names

_NAMES = {
    **dict.fromkeys(
        (
            "OUT_SUFFIXES",
            "BatchFile",
            "Job",
            "batch_file",
            "check",
            "check_output_file",
            "compute",
            "join",
            "plan",
        ),
        "job",
    ),
    "OUTPUTS": "parts",
    "impact_batch": "stream",
}
__all__ = sorted(_NAMES)

__getattr__ = lazy_names(__name__, _NAMES, globals())
