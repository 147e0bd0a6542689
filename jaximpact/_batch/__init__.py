"""Many impacts at once, arrays in and arrays out: `run_batch` over devices in blocks
(`runner`), `impact_batch` over rows of parameters (`impacts`: the rows checked once, then
`run_impacts` on the path chosen once), tables written to files (`table`). Tables read from
disk in chunks are `_jobs`'. Imports `_solve` and `_laws`."""

from .impacts import (
    IMPACT_FIELDS as IMPACT_FIELDS,
    IMPACT_OPTIONS as IMPACT_OPTIONS,
    Impacts as Impacts,
    batch_path as batch_path,
    build_law as build_law,
    cost_key as cost_key,
    impact_batch as impact_batch,
    law_skeleton as law_skeleton,
    mark_invalid as mark_invalid,
    prepare_rows as prepare_rows,
    run_impacts as run_impacts,
)
from .runner import GLOBAL as GLOBAL, block_length as block_length, run_batch as run_batch
from .table import write_table as write_table
