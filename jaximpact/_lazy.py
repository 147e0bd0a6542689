"""A subpackage's names loaded with their module on first use (PEP 562), so that importing
one light module of it does not import its heavy siblings (diffrax, the batch)."""

import importlib


def lazy_names(package: str, names: dict[str, str], namespace: dict):
    """The module `__getattr__` of `package` (its `__name__`) for `names` ({name: the
    submodule that defines it}): the first look-up imports the submodule and keeps the
    value in `namespace` (the package's `globals()`), so later look-ups skip it."""

    def __getattr__(name):
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{names[name]}", package), name)
        namespace[name] = value
        return value

    return __getattr__
