"""Tables on disk, a layer above `_batch` (arrays in, arrays out): `batch_file` reads a CSV or
Parquet file of bodies (or a script's chunks), checks every row once, computes the chunks
through `_batch` on one process or several, and joins the parts into the output (`job`:
`plan`, `check`, `compute`, `join`); `impact_batch` takes arrays to `_batch` and chunks to
a file. Imports `_batch`, `_laws` and the leaf helpers."""

from .job import (
    OUT_SUFFIXES as OUT_SUFFIXES,
    BatchFile as BatchFile,
    Job as Job,
    batch_file as batch_file,
    check as check,
    check_output_file as check_output_file,
    compute as compute,
    join as join,
    plan as plan,
)
from .parts import OUTPUTS as OUTPUTS
from .stream import impact_batch as impact_batch
