"""Many impacts at once: `run_batch` over devices in blocks, `impact_batch` over rows of
parameters, tables written to files. Imports `_solve` and `_laws`."""
