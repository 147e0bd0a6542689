"""Where curves live: the file shipped with the package, and a cache for other shapes.

The shipped file holds the shapes of the law table's rows (`SHIPPED`); a shape that is not
there (Hunt-Crossley with another `n`, a power law with the user's own `n` and `p`) is
built on first use and kept in `$JAXIMPACT_CURVES_DIR` (default
`$XDG_CACHE_HOME/jaximpact/curves`, else `~/.cache/jaximpact/curves`). Every file carries
a format version and a SHA-256 of its arrays and key: a file that does not match (corrupt,
truncated, from another version or for another shape) is rebuilt, never trusted.
`python -m jaximpact._curves.ship` rebuilds the shipped file.
"""

import functools
import hashlib
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from .._laws import SHIPPED_SHAPES
from .curve import DEGREE, OUTPUTS, Curves
from .shapes import CurveKey, curve_key

FORMAT = 1
SHIPPED_FILE = Path(__file__).with_name("curves.npz")
# the shapes of the law table's one-group rows, under both criteria (`table.SHIPPED_SHAPES`)
SHIPPED = tuple(
    dict.fromkeys(curve_key(n, p, s) for n, p in SHIPPED_SHAPES for s in ("force", "penetration"))
)
_ENV = "JAXIMPACT_CURVES_DIR"


class CorruptCurves(ValueError):
    """A curves file that does not hold what it claims."""


def cache_dir() -> Path:
    value = os.environ.get(_ENV, "").strip()
    if value:
        return Path(value).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "jaximpact" / "curves"


def _digest(name: str, arrays: dict) -> str:
    sha = hashlib.sha256(f"{FORMAT}:{name}".encode())
    for field in sorted(arrays):
        sha.update(field.encode())
        sha.update(np.ascontiguousarray(arrays[field], dtype=float).tobytes())
    return sha.hexdigest()


def _arrays(curves: Curves) -> dict:
    capture = np.nan if curves.capture is None else curves.capture
    return dict(
        breaks=curves.breaks,
        coefficients=curves.coefficients,
        tail=curves.tail,
        meta=np.array([FORMAT, curves.key.n, curves.key.p, curves.beta_max, capture]),
    )


def save(curves_list, path: Path):
    """Write curves to `path` atomically (a temporary file renamed into place)."""
    content = {}
    for curves in curves_list:
        arrays = _arrays(curves)
        name = curves.key.name
        content.update({f"{name}/{field}": value for field, value in arrays.items()})
        content[f"{name}/sha256"] = np.array(_digest(name, arrays))
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, suffix=".npz")
    os.close(handle)
    np.savez(temporary, **content)
    os.chmod(temporary, 0o644)
    os.replace(temporary, path)


def _checked(name: str, arrays: dict) -> Curves:
    digest = str(arrays.pop("sha256"))
    if digest != _digest(name, arrays):
        raise CorruptCurves(f"curves {name}: checksum mismatch")
    version, n, p, beta_max, capture = arrays["meta"]
    key = CurveKey(float(n), float(p), name.rsplit(",", 1)[-1])
    breaks, coefficients, tail = arrays["breaks"], arrays["coefficients"], arrays["tail"]
    pieces = breaks.shape[0] - 1
    if (
        version != FORMAT
        or key.name != name
        or pieces < 1
        or coefficients.shape != (pieces, DEGREE + 1, len(OUTPUTS))
        or tail.shape != (pieces, len(OUTPUTS))
        or not np.all(np.diff(breaks) > 0)
        or not np.all(np.isfinite(coefficients))
    ):
        raise CorruptCurves(f"curves {name}: arrays of the wrong form")
    capture = None if np.isnan(capture) else float(capture)
    return Curves(key, breaks, coefficients, float(beta_max), capture, tail)


def read_groups(path: Path, error, what: str) -> dict:
    """The arrays of an `.npz` file of tables, grouped by table: `{name: {part: array}}`
    from its fields `name/part`; `error(message)` (an exception class) if it is not such a
    file (`what` names the kind, e.g. "curves file")."""
    try:
        with np.load(path, allow_pickle=False) as data:
            fields = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as reason:
        raise error(f"{path}: not a {what} ({reason})") from None
    grouped = {}
    for field, value in fields.items():
        name, _, part = field.rpartition("/")
        grouped.setdefault(name, {})[part] = value
    return grouped


def load(path: Path) -> dict:
    """`{CurveKey: Curves}` from a file; `CorruptCurves` if anything does not check."""
    grouped = read_groups(path, CorruptCurves, "curves file")
    try:
        curves = [_checked(name, arrays) for name, arrays in grouped.items()]
    except (KeyError, TypeError, ValueError) as error:
        raise CorruptCurves(f"{path}: {error}") from None
    return {c.key: c for c in curves}


@functools.cache
def shipped() -> dict:
    return load(SHIPPED_FILE) if SHIPPED_FILE.exists() else {}


def _cache_file(key: CurveKey) -> Path:
    return cache_dir() / f"curves_n{key.n!r}_p{key.p!r}_{key.separation}_v{FORMAT}.npz"


@functools.cache
def curves_for(key: CurveKey, progress: bool = True) -> Curves:
    """The curves of `key`: shipped, cached on disk, or built now (and cached)."""
    if key in shipped():
        return shipped()[key]
    path = _cache_file(key)
    if path.exists():
        try:
            cached = load(path).get(key)
        except CorruptCurves:
            cached = None
        if cached is not None:
            return cached
    from .build import build_curves  # diffrax, only when a shape must be built

    curves = build_curves(key, progress=progress)
    try:
        save([curves], path)
    except OSError:
        pass  # an unwritable cache costs a rebuild next time, nothing else
    return curves
