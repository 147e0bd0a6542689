"""A fit read back from its file: the JSON object that `jaximpact calibrate --json` writes,
from a path or from stdin (`read_fit_file`), each way it can fail a one-line ValueError
naming `--from PATH` (the one reading of a fit's file, for `export --from` and `fit-oblique
--from`)."""

import json
import sys
from pathlib import Path

from .report import fit_from_json


def read_fit_file(path: str, law: str | None = None, *, user_law=None):
    """`(data, record, fit)` of the JSON file `path` ('-': stdin) that `jaximpact calibrate
    --json` writes: the whole object, the one fit in it (one law; of `--law all`'s ranking
    its best, or the law `law` names) and that fit read back (`fit_from_json`, with its
    `user_law`: what builds a user's law FILE.py:NAME from its parameters)."""
    where, hint = f"--from {path}", "write it with 'jaximpact calibrate ... --json > FILE'"
    try:
        data = json.loads(sys.stdin.read() if path == "-" else Path(path).read_bytes())
    except OSError as error:
        raise ValueError(f"{where}: cannot read it ({error.strerror or error})") from None
    except UnicodeDecodeError as error:
        raise ValueError(f"{where}: not JSON ({error.reason}); {hint}") from None
    except json.JSONDecodeError as error:
        raise ValueError(f"{where}: not JSON ({error.msg}, line {error.lineno}); {hint}") from None
    return (data, *fit_from_json(data, law, source=path, user_law=user_law))
