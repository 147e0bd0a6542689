"""The law of a file job, as the job reads it (`JobLaw`): a name of the law table, a law of
the table (`jaximpact.law`: its parameters are the values every row takes unless a column
or `params` gives them) or a user's law (`custom_law`: its parameters are those it holds,
those `params` gives and the table's columns that are not `m`, `v0`, `g`, `separation` and
that its function reads; every one that `params` gives, or a column naming one it holds,
must be read by its function; any other column is carried through to the output).

A resumed job reuses a chunk only where the law is the same (`JobLaw.identity`, hashed with
each chunk's inputs): a table law's name; for a user's law its name, the function's module,
qualified name and source file, a SHA-256 of that file (else of its compiled code), and
what its closure and defaults hold. Its parameter values are hashed as every value given
for all rows is (`job.plan`)."""

import dataclasses
import hashlib
import inspect
import json
import marshal
from collections.abc import Callable, Mapping
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from .._batch import law_skeleton
from .._choices import unknown_name
from .._laws import LAW_NAMES, LAWS, AbstractLaw, law as make_law
from .._laws.named_law import invalid_parameter_rows
from .readers import TEXT_COLUMNS, close_column
from .row_checks import KINEMATICS, option_name


class MissingParameter(KeyError):
    """A user's function read `params[key]` where no value is given (`parameters_read`)."""


def parameters_read(fn: Callable, names) -> tuple[str, ...]:
    """The parameters among `names` that a user's law `fn(x, v, params)` reads, found by
    tracing it once with no numbers (`jax.eval_shape`). A `MissingParameter` (a `KeyError`
    holding the name) where it reads one that `names` lacks, unless it catches that itself
    (`params.get("a", 0.2)`); any other error of the function is its own."""
    read = []

    class Reads(Mapping):
        def __init__(self, values):
            self._values = values

        def __getitem__(self, key):
            if key not in self._values:
                raise MissingParameter(key)
            if key not in read:
                read.append(key)
            return self._values[key]

        def __iter__(self):  # a function that takes every parameter reads every one
            read.extend(k for k in self._values if k not in read)
            return iter(self._values)

        def __len__(self):
            return len(self._values)

    scalar = jax.ShapeDtypeStruct((), jnp.result_type(float))
    jax.eval_shape(lambda x, v, p: fn(x, v, Reads(p)), scalar, scalar, dict.fromkeys(names, scalar))
    return tuple(read)


@dataclasses.dataclass(frozen=True)
class JobLaw:
    """What a file job reads of its law: `label` (its name in messages and meters: the
    table's name, or a user's law's `name`), `skeleton` (`_batch`'s structure of the law,
    for `run_impacts`), `parameters` (the names a column or `params` may give, in order),
    `defaults` (the values every row takes unless given), `positive` (the parameters that
    must be > 0; the others >= 0, or any finite number for a user's law), `shape_parameters`
    (those that choose a compiled program: `chunks` groups rows by them), `identity` (text
    that a resume compares) and `fn` (a user's function, else None)."""

    label: str
    skeleton: tuple
    parameters: tuple
    defaults: dict
    positive: tuple = ()
    shape_parameters: tuple = ()
    identity: str = ""
    fn: Callable | None = None

    @property
    def user(self) -> bool:
        """A user's law: no row of the law table."""
        return self.fn is not None

    @property
    def known_columns(self) -> tuple:
        """The columns a job reads (a user's law: once `complete`d); any other is carried
        through to the output (`readers.carried_columns`)."""
        return (*self.parameters, *KINEMATICS, *TEXT_COLUMNS)

    def invalid_rows(self, params: dict) -> np.ndarray:
        """The rows whose parameters break a rule of the law table beyond the signs
        (`e_nominal <= 1`, `p <= n`); none for a user's law (finite is all it needs)."""
        if self.user:
            rows = len(next(iter(params.values()), ()))
            return np.zeros(rows, bool)
        return invalid_parameter_rows(self.label, params)

    def refusal(self, row: dict) -> str:
        """Why the law refuses the parameters of one row (`invalid_rows`), in words."""
        try:
            make_law(self.label, **row)
        except ValueError as error:
            return str(error)
        return "the law's parameters are out of range"

    def complete(self, columns, params: dict, where: str) -> "JobLaw":
        """A user's law with its `parameters` named by its own, by `params` and by the
        table's `columns` that its function reads (those not `m`, `v0`, `g`,
        `separation`; the others are carried through), each checked against what its
        function reads: a one-line `ValueError` for a parameter it reads that none gives,
        and for a value of `params`, or a column naming a parameter it holds, that it does
        not read (`where`: the table, for messages). A table law as it is."""
        if not self.user:
            return self
        own = (*KINEMATICS, *TEXT_COLUMNS)
        from_columns = [k for k in columns if k not in own]
        names = tuple(dict.fromkeys((*self.defaults, *params, *from_columns)))
        try:
            read = parameters_read(self.fn, names)
        except MissingParameter as error:
            key = error.args[0]
            near = close_column(key, from_columns)
            hint = f" (column {near!r} is not {key})" if near is not None else ""
            raise ValueError(
                f"{self.label} reads params[{json.dumps(key)}]: give a column {key} or a "
                f"value for every row, {option_name(key)}{hint}"
            ) from None
        reads = f"it reads {', '.join(read)}" if read else "it reads no parameter"
        for key in from_columns:
            if key not in read and (key in self.defaults or key in params):
                raise ValueError(
                    f"{where}: column {key!r} is not a parameter of {self.label} ({reads}; "
                    f"the other columns may be {', '.join(own)})"
                )
        for key in params:
            if key not in read:
                raise ValueError(
                    f"{option_name(key)}: {self.label} does not read "
                    f"params[{json.dumps(key)}] ({reads})"
                )
        carried = [k for k in from_columns if k not in read]  # `readers.carried_columns`
        return dataclasses.replace(self, parameters=tuple(k for k in names if k not in carried))


def job_law(law) -> JobLaw:
    """The `JobLaw` of `batch_file`'s `law`: a name of `LAW_NAMES`, a law of the table or a
    user's law (`custom_law`); a one-line `ValueError` for anything else, and for a law
    whose parameters are not one number each (per-row values are a table's columns)."""
    if isinstance(law, str):
        if law not in LAWS:
            raise ValueError(unknown_name("law", law, LAW_NAMES))
        return _table_law(LAWS[law], {})
    if not isinstance(law, AbstractLaw):
        raise ValueError(
            "law must be a name of LAW_NAMES, a law from jaximpact.law or a user's law from "
            f"custom_law, got {type(law).__name__}"
        )
    values = {}
    for key, value in law.parameters.items():
        array = np.asarray(value, dtype=float)
        if array.size != 1:
            raise ValueError(
                f"law {law.name!r}: parameter {key} holds {array.size} values; a file job's "
                "law holds one number per parameter (per-row values are the table's columns)"
            )
        values[key] = float(array.reshape(()))
    if law.spec is not None:
        return _table_law(law.spec, values)
    fn = law.fn
    return JobLaw(
        label=law.name,
        skeleton=law_skeleton(law),
        parameters=tuple(values),
        defaults=values,
        identity=json.dumps(["user", law.name, *function_identity(fn)]),
        fn=fn,
    )


def _table_law(spec, values: dict) -> JobLaw:
    """A law of the table's row `spec`, its own parameter `values` over the row's defaults."""
    return JobLaw(
        label=spec.name,
        skeleton=("law", spec.name),
        parameters=tuple(spec.parameters),
        defaults={**spec.defaults, **values},
        positive=tuple(spec.positive),
        shape_parameters=tuple(spec.shape_parameters),
        identity=spec.name,
    )


def function_identity(fn: Callable) -> list[str]:
    """What tells a user's function from another across runs: its module, qualified name
    and source file, a SHA-256 of that file (any edit of it changes the law; else of its
    compiled code), and a description of what its closure and defaults hold."""
    fn = inspect.unwrap(fn)
    code = getattr(fn, "__code__", None)
    try:
        file = inspect.getsourcefile(fn)
    except TypeError:  # a callable object: its class's file
        file = inspect.getsourcefile(type(fn)) if _has_source(type(fn)) else None
    if file is not None and Path(file).is_file():
        digest = hashlib.sha256(Path(file).read_bytes()).hexdigest()
    elif code is not None:
        digest = hashlib.sha256(marshal.dumps(code)).hexdigest()
    else:
        digest = ""
    held = [
        *(getattr(fn, "__defaults__", None) or ()),
        *(cell.cell_contents for cell in (getattr(fn, "__closure__", None) or ())),
    ]
    return [
        str(getattr(fn, "__module__", None) or type(fn).__module__),
        str(getattr(fn, "__qualname__", None) or type(fn).__qualname__),
        str(Path(file).resolve()) if file is not None else "",
        digest,
        hashlib.sha256("\n".join(map(_described, held)).encode()).hexdigest(),
    ]


def _has_source(cls) -> bool:
    try:
        return inspect.getsourcefile(cls) is not None
    except TypeError:  # a built-in class
        return False


def _described(value) -> str:
    """A value a user's function holds, as text that is the same in every run: a function
    by its name, an array by its bytes, anything else by its `repr`."""
    if callable(value):
        inner = inspect.unwrap(value)
        return f"{getattr(inner, '__module__', '')}.{getattr(inner, '__qualname__', '')}"
    if isinstance(value, (np.ndarray, jax.Array)):
        array = np.asarray(value)
        return f"{array.dtype}{array.shape}{hashlib.sha256(array.tobytes()).hexdigest()}"
    return repr(value)
