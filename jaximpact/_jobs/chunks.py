"""One chunk of a table computed: its rows (checked once, by `row_checks`) grouped so that
each row's path depends on that row alone, each group through `_batch.run_impacts` (no
check again, the path chosen once per group), and the results as a part's columns
(`parts.OUTPUTS`): the float results, the `status` names and the `path` of every row.

Under `mesh="global"` every process computes its chunk of the round at once, each row group
as one program over the devices of them all (`run_batch(devices="global")`)."""

import json

import numpy as np

from .._batch import GLOBAL, mark_invalid, run_impacts
from .._status import Status
from .parts import FLOAT_OUTPUTS
from .processes import ProcessGroup

_STATUS_NAMES = np.array(
    [
        Status(i).name if i in set(map(int, Status)) else ""
        for i in range(max(map(int, Status)) + 1)
    ],
    object,
)


def compute_chunk(law, cells, fixed: dict, options: dict, group: ProcessGroup | None) -> dict:
    """The impacts of one chunk (`cells`, whose values `row_checks` accepted; `law`: a
    `job_law.JobLaw`; `fixed`: the values given for every row; `options`: `impact`'s
    keywords); rows grouped by separation, by whether gravity is zero and by the law's
    shape parameters, so that each row's path depends on that row alone (not on the chunk
    it falls in). Returns `OUTPUTS` -> one entry per row.

    With `group`, every process of it calls `compute_chunk` at once (`cells` None where it
    has nothing to compute): the processes agree on the row groups of the round, and each
    row group runs as one program over the devices of them all (`devices="global"`), every
    process giving the same number of rows: the group's first row of the first process
    that has it (so that every process takes the same path and shapes), its own rows, and
    that first row again as padding."""
    rows = 0 if cells is None else cells.rows
    values = {} if cells is None else cells.values
    given = {
        k: np.broadcast_to(np.asarray(v, float), (rows,))
        for k, v in fixed.items()
        if k != "separation"
    }
    given.update({k: v for k, v in values.items() if k != "separation"})
    given.setdefault("g", np.zeros(rows))
    sep = values.get("separation", np.full(rows, fixed.get("separation", "force"), object))
    columns = (*law.parameters, "m", "v0", "g")
    local = _row_groups(law, given, sep, values) if rows else {}  # key -> this chunk's rows
    plan = {key: (None, idx.size) for key, idx in local.items()}  # key -> (first row, rows)
    if group is not None:
        plan = _shared_plan(group, local, given, columns)
    results = {k: np.full(rows, np.nan) for k in FLOAT_OUTPUTS}
    status = np.empty(rows, object)
    path = np.empty(rows, object)
    for key in sorted(plan):
        idx = local.get(key, np.zeros(0, int))
        inputs = {k: np.asarray(given.get(k, np.zeros(0)), float)[idx] for k in columns}
        first, size = plan[key]
        if group is not None:  # the first row, this process's rows, the first row as padding
            inputs = {
                k: np.concatenate([[first[j]], inputs[k], np.full(size - idx.size, first[j])])
                for j, k in enumerate(columns)
            }
        done = run_impacts(
            law.skeleton,
            {k: inputs[k] for k in law.parameters},
            {k: inputs[k] for k in ("m", "v0", "g")},
            separation=json.loads(key)[0],
            fields=(*FLOAT_OUTPUTS, "status"),
            progress=False,
            **({"devices": GLOBAL} if group is not None else {}),
            **{"rtol": None, **options},  # as `impact`: 1e-11, a user's law 1e-12
        )
        if not idx.size:
            continue
        out = mark_invalid(done.out, done.lost)  # results float64 cannot hold: invalid
        mine = slice(1, 1 + idx.size) if group is not None else slice(None)
        for k in FLOAT_OUTPUTS:
            results[k][idx] = out[k][mine]
        status[idx] = _STATUS_NAMES[out["status"][mine]]
        path[idx] = done.paths[mine]  # "grid" for the rows the grid served
    return {**results, "status": status.tolist(), "path": path.tolist()}


def _row_groups(law, given: dict, sep, values: dict) -> dict:
    """The rows of a chunk by group, `json` key `[separation, g == 0, shape parameters]` ->
    row indices: the rows that share a path and a compiled program."""
    keys = [np.unique(sep, return_inverse=True)[1]] if "separation" in values else []
    keys += [given["g"] == 0.0] if "g" in values else []
    keys += [
        np.unique(values[k], return_inverse=True)[1] for k in law.shape_parameters if k in values
    ]
    group_of = np.zeros(len(sep), int)
    if keys:
        _, group_of = np.unique(np.stack(keys, axis=1), axis=0, return_inverse=True)
        group_of = group_of.reshape(-1)
    groups = {}
    for number in range(int(group_of.max()) + 1):
        idx = np.flatnonzero(group_of == number)
        shape = [float(given[k][idx[0]]) for k in law.shape_parameters]
        groups[json.dumps([str(sep[idx[0]]), bool(given["g"][idx[0]] == 0.0), shape])] = idx
    return groups


def _shared_plan(group: ProcessGroup, local: dict, given: dict, columns) -> dict:
    """Every process's row groups of the round (`local`: this one's), each key -> (the values
    of `columns` in its first row on the first process that has it, the most rows any
    process has of it): the same on every process."""
    shared = {
        key: ([float(given[k][idx[0]]) for k in columns], int(idx.size))
        for key, idx in local.items()
    }
    plan = {}
    for theirs in group.gather(shared):
        for key, (first, size) in theirs.items():
            known_first, known_size = plan.get(key, (first, 0))
            plan[key] = (known_first, max(known_size, size))
    return plan
