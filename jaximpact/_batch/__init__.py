"""Many impacts at once: `run_batch` over devices in blocks (`runner`), `impact_batch` over
rows of parameters (`impacts`), tables written to files (`table`). Imports `_solve` and
`_laws`."""

from .impacts import (
    IMPACT_FIELDS as IMPACT_FIELDS,
    batch_path as batch_path,
    build_law as build_law,
    cost_key as cost_key,
    impact_batch as impact_batch,
    prepare_rows as prepare_rows,
)
from .runner import block_length as block_length, run_batch as run_batch
from .table import write_table as write_table
