"""A user's law named as the command line names it, `FILE.py:NAME` (`--law`): the function
NAME(x, v, params) of a Python file (`_laws.custom.load_law_function`) with its parameters,
checked by tracing it once (`job_law.parameters_read`): a parameter it reads that is not
given, or one given that it does not read, is a one-line ValueError. `make_law` builds a
law of the table or such a law from its name and parameters."""

import json

from .job_law import MissingParameter, parameters_read


def make_law(name: str, params: dict):
    """The law `name` (of the table, or a user's `FILE.py:NAME`) with `params`."""
    if is_file_law(name):
        return file_law(name, params)
    from .._laws import law

    return law(name, **params)


def is_file_law(name) -> bool:
    """Whether `--law name` names a user's law, `FILE.py:NAME` (a table name has no colon;
    a name ending in `.py` is a file whose function is not named: `load_law_function` says
    so)."""
    return isinstance(name, str) and (":" in name or name.endswith(".py"))


def file_law(text: str, params: dict, *, complete: bool = True):
    """The user's law `FILE.py:NAME` (`text`, its name in all output) with the parameters
    `params` (`--param`): `custom_law(fn, **params)` of the function NAME of the file.
    With `complete`, its function is traced once (no numbers, no compilation): a
    parameter it reads that `params` lacks (its `KeyError`), or one of `params` it does not
    read, is a one-line ValueError; without (`jaximpact batch`, whose table's columns may
    give parameters), the job checks them."""
    from .._laws import CustomLaw, custom_law
    from .._laws.custom import load_law_function

    fn = load_law_function(text)
    law = custom_law(fn, **params) if params else CustomLaw(fn, {}, text)
    law = CustomLaw(law.fn, law.params, text)
    if complete:
        check_file_law(law)
    return law


def check_file_law(law):
    """One-line ValueErrors for a user's law of the command line (`file_law`) whose function
    reads a parameter that `--param` does not give, fails when traced, or is given a
    parameter it does not read."""
    from .._laws.custom import first_line, line_in

    text = law.name
    try:
        read = parameters_read(law.fn, law.params)
    except MissingParameter as error:
        key = error.args[0]
        raise ValueError(
            f"{text} reads params[{json.dumps(key)}]: give it with --param {key}=..."
        ) from None
    except Exception as error:  # the user's function: where it failed, in one line
        raise ValueError(
            f"{text} failed when called as NAME(x, v, params) with numbers ("
            f"{type(error).__name__}{line_in(error, law.fn)}: {first_line(error)})"
        ) from None
    unread = [k for k in law.params if k not in read]
    if unread:
        reads = ", ".join(read) or "no parameter"
        raise ValueError(
            f"--param {unread[0]}: {text} does not read params["
            f"{json.dumps(unread[0])}] (it reads {reads})"
        )
