"""Programs kept on disk as traced, so that a second process neither traces nor compiles them.

JAX's persistent cache (`enable_cache`, the command line) keeps XLA's compiled programs, but
a new process still traces the Python that makes them: `fit_oblique`'s one program 7-9 CPU s
of its 10-15, a closed-form fit 1-3 s. Where that cache is on, a program of `stored_jit` is
also kept as traced: `jax.export`'s serialized StableHLO, with the structure of its output,
in `<the cache>/jaximpact-programs/<key>.program`. A later process with the same key loads it
(milliseconds), and XLA's compile of it is found in JAX's cache.

The key is everything the trace depends on, hashed:

- the program (its module and name) and the source of this package (every file of it);
- the versions of JAX, jaxlib and the libraries that trace with it, and the settings that
  change a trace (64-bit floats, promotion, matmul precision, equinox's `EQX_ON_ERROR`),
  the backend and its devices;
- the arguments: the shape and dtype of every array (traced), and every other leaf and
  static field by value.

An argument that cannot be told apart by value keeps the program in memory only (traced as
`eqx.filter_jit` does): a function or class not of this package and the libraries it traces
with (a user's law), a closure, an object of another kind. So does a call under a transform
(tracers in the arguments), a program `jax.export` refuses (a host callback: in a Python
session, lineax's checks in the derivative of diffrax's event times, which the command
line turns into NaN), JAX's checks (`jax_debug_nans`, `jax_disable_jit`), and a cache that
cannot be written.
"""

import dataclasses
import enum
import functools
import hashlib
import importlib
import importlib.metadata
import io
import os
import pickle
import sys
import tempfile
import threading
import types
from pathlib import Path

import equinox as eqx
import jax
import numpy as np

# where a static function, class or object may come from: this package (its source is in the
# key) and the libraries whose versions are
_LIBRARIES = ("jax", "jaxlib", "diffrax", "equinox", "optimistix", "lineax", "optax", "numpy")
_MODULES = ("jaximpact", "builtins", *_LIBRARIES)
_FORMAT = "jaximpact-program-1"
_FOLDER = "jaximpact-programs"
_SUFFIX = ".program"
_REFUSED = ".refused"  # a program `jax.export` refused: traced in memory from then on


class _NotStorable(Exception):
    """An argument that the key cannot tell apart by value."""


def _from_known_module(thing) -> str:
    """`module.qualname` of a class or function of `_MODULES` defined at a module's top."""
    module = getattr(thing, "__module__", None) or ""
    name = getattr(thing, "__qualname__", None) or ""
    if module.split(".")[0] not in _MODULES or not name or "<" in name:
        raise _NotStorable(f"{thing!r}")
    return f"{module}.{name}"


def _value(obj, out: list) -> None:
    """Append to `out` a text that tells `obj` (a static leaf or field) apart by value."""
    if obj is None or isinstance(obj, (bool, int, float, complex, str, bytes)):
        out.append(f"{type(obj).__name__}:{obj!r}")
    elif isinstance(obj, (tuple, list)):
        out.append(f"{type(obj).__name__}[{len(obj)}")
        for item in obj:
            _value(item, out)
        out.append("]")
    elif type(obj) is dict:
        out.append(f"dict[{len(obj)}")
        for k, item in obj.items():
            _value(k, out)
            _value(item, out)
        out.append("]")
    elif isinstance(obj, type):
        out.append(f"type:{_from_known_module(obj)}")
    elif isinstance(obj, (types.FunctionType, types.BuiltinFunctionType, np.ufunc)):
        out.append(f"function:{_from_known_module(obj)}")
    elif isinstance(obj, enum.Enum):
        out.append(f"enum:{_from_known_module(type(obj))}.{obj.name}")
    elif isinstance(obj, np.dtype):
        out.append(f"dtype:{obj.str}")
    elif isinstance(obj, eqx.Module) or dataclasses.is_dataclass(obj):
        out.append(f"object:{_from_known_module(type(obj))}[")
        for field in dataclasses.fields(obj):
            out.append(field.name)
            if eqx.is_array(value := getattr(obj, field.name, None)):
                raise _NotStorable("an array in a static field")
            _value(value, out)
        out.append("]")
    elif (where := _global_name(obj)) is not None:  # equinox's `MISSING`: one a process
        out.append(f"global:{_from_known_module(type(obj))}:{where[0]}.{where[1]}")
    else:
        raise _NotStorable(f"{type(obj)!r}")


def _global_name(obj):
    """`(module, name)` where `obj` is that module's global of that name, else None."""
    module = getattr(type(obj), "__module__", "")
    if module.split(".")[0] not in _MODULES or module == "builtins":
        return None
    names = vars(sys.modules.get(module, types.ModuleType("none")))
    for name, value in names.items():
        if value is obj:
            return module, name
    return None


def _tree(treedef, out: list) -> None:
    """Append to `out` a text of a pytree's structure: its node types and their static
    data (equinox's static fields)."""
    data = treedef.node_data()
    if data is None:
        out.append("*")
        return
    kind, aux = data
    out.append(f"node:{_from_known_module(kind)}(")
    _value(aux, out)
    for child in treedef.children():
        _tree(child, out)
    out.append(")")


@functools.cache
def _environment() -> str:
    """The versions and the source that every key shares: this package's files, hashed."""
    digest = hashlib.sha256(_FORMAT.encode())
    for name in _LIBRARIES:
        try:
            version = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            version = "-"
        digest.update(f"{name}={version};".encode())
    root = Path(__file__).resolve().parent
    for path in sorted(root.rglob("*")):
        if path.is_file() and path.suffix in (".py", ".npz", ".json", ".csv"):
            digest.update(str(path.relative_to(root)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def _settings() -> str:
    """JAX's settings that change a trace, the devices it runs on, and how equinox's
    run-time checks fail (`EQX_ON_ERROR`, read when equinox loads: the command line's
    NaN, a Python session's raise)."""
    config = jax.config
    return ";".join(
        str(x)
        for x in (
            _equinox_on_error(),
            config.jax_enable_x64,
            config.jax_numpy_dtype_promotion,
            config.jax_numpy_rank_promotion,
            config.jax_default_matmul_precision,
            jax.default_backend(),
            jax.device_count(),
        )
    )


def _equinox_on_error() -> str:
    """equinox's `EQX_ON_ERROR` as it read it when it loaded (the environment's now, where
    this equinox keeps it elsewhere)."""
    try:
        from equinox._config import EQX_ON_ERROR
    except ImportError:
        return os.environ.get("EQX_ON_ERROR", "raise")
    return EQX_ON_ERROR


@functools.cache
def _can_serialize() -> bool:
    """Whether `jax.export` can write a program here (it needs `flatbuffers`)."""
    try:
        import flatbuffers  # noqa: F401
    except ImportError:
        return False
    return True


def _folder() -> Path | None:
    """`<JAX's persistent cache>/jaximpact-programs`, None where that cache is off, JAX's
    checks are on, `jax.export` cannot serialize, there is more than one device, or the
    folder cannot be made."""
    config = jax.config
    if (
        not _can_serialize()
        or config.jax_compilation_cache_dir is None
        or jax.device_count() != 1  # a program is exported for one device
        or config.jax_disable_jit
        or config.jax_debug_nans
        or config.jax_debug_infs
    ):
        return None
    return _made(str(config.jax_compilation_cache_dir))


@functools.cache
def _made(cache: str) -> Path | None:
    """`<cache>/jaximpact-programs`, made once per process (None: it cannot be)."""
    folder = Path(cache) / _FOLDER
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder


class _Pickler(pickle.Pickler):
    """Pickles an output's structure, a module-level object (equinox's `MISSING`, whose
    identity its unflattening tests) by its name."""

    def persistent_id(self, obj):
        if isinstance(obj, (type, types.FunctionType, str, int, float, bool, tuple)):
            return None
        return _global_name(obj)


class _Unpickler(pickle.Unpickler):
    def persistent_load(self, pid):
        module, name = pid
        return getattr(importlib.import_module(module), name)


def _dumps(obj) -> bytes:
    buffer = io.BytesIO()
    _Pickler(buffer, protocol=pickle.HIGHEST_PROTOCOL).dump(obj)
    return buffer.getvalue()


def _loads(data: bytes):
    return _Unpickler(io.BytesIO(data)).load()


@dataclasses.dataclass(frozen=True)
class _Program:
    """A loaded or freshly traced program: the exported call, and how its array outputs
    go back into the output's structure."""

    call: object
    out_tree: object
    out_static: tuple  # the output's leaves that are not arrays, None at arrays


def _assemble(program: _Program, arrays):
    arrays = iter(arrays)
    leaves = [next(arrays) if s is None else s[0] for s in program.out_static]
    return program.out_tree.unflatten(leaves)


def stored_jit(fun, *, eager_options=None, **jit_options):
    """`eqx.filter_jit(fun, **jit_options)`, kept on disk as traced where JAX's persistent
    cache is on (this module's docstring says when). The same values, bitwise: the same
    StableHLO, compiled with the same options.

    `eager_options`: None, or a function of no arguments giving the compiler's options
    (a dict, `{}` for none) of a call on its own, with no transform or `jit` around it;
    inside one the outer program's options hold (a nested `jit` may not set them)."""
    plain = eqx.filter_jit(fun, **jit_options)
    eager_plain = []  # made at the first call on its own
    programs: dict[str, _Program | None] = {}
    lock = threading.Lock()
    try:  # only this package's own top-level functions: their source is in the key
        name = _from_known_module(fun)
        storable = name.startswith("jaximpact.")
    except _NotStorable:
        storable = False

    @functools.wraps(fun)
    def call(*args, **kwargs):
        leaves, treedef = jax.tree_util.tree_flatten((args, kwargs))
        arrays = [x for x in leaves if eqx.is_array(x)]
        if any(isinstance(x, jax.core.Tracer) for x in arrays) or not _on_its_own():
            return plain(*args, **kwargs)
        options = _eager_options(jit_options, eager_options)
        folder = _folder() if storable else None
        if folder is None:
            if not eager_plain:
                with lock:
                    if not eager_plain:
                        eager_plain.append(eqx.filter_jit(fun, **options))
            return eager_plain[0](*args, **kwargs)
        try:
            key = _key(name, options, leaves, treedef)
        except _NotStorable:
            return plain(*args, **kwargs)
        program = programs.get(key)
        if program is None and key not in programs:
            with lock:
                if key not in programs:
                    found, program = _load(folder, key, options)
                    if not found:
                        program = _trace(fun, folder, key, options, leaves, treedef)
                    programs[key] = program
                program = programs[key]
        if program is None:
            return plain(*args, **kwargs)
        return _assemble(program, program.call(*arrays))

    return call


try:  # JAX's own test that no trace is under way (private: absent from some version)
    from jax._src.core import trace_state_clean as _trace_state_clean
except ImportError:
    _trace_state_clean = None


def _on_its_own() -> bool:
    """Whether no trace is under way around this call (JAX's own test, where this
    version has it; else False: the outer program's options, as inside a transform)."""
    return _trace_state_clean is not None and bool(_trace_state_clean())


def _eager_options(jit_options: dict, eager_options) -> dict:
    """`jit_options` with `eager_options()` as the compiler's options, where given."""
    compiler = eager_options() if eager_options is not None else {}
    return {**jit_options, "compiler_options": compiler} if compiler else jit_options


def _array_text(leaf) -> str:
    weak = getattr(leaf, "weak_type", False)
    return f"array:{np.dtype(leaf.dtype).str}{tuple(leaf.shape)}{weak}"


# the keys already worked out in this process, by what they are worked out from (a call's
# structure, its leaves that are not arrays, with their types: 1 == 1.0 == True)
_KEYS: dict = {}


def _key(name, jit_options, leaves, treedef) -> str:
    """The hashed key of a call (this module's docstring): about 10 us where this process
    has seen the call's structure before, 100-150 us the first time."""
    settings = _settings()
    try:
        memo = (
            name,
            settings,
            treedef,
            *[_array_text(x) if eqx.is_array(x) else (type(x), x) for x in leaves],
        )
        return _KEYS[memo]
    except KeyError:
        pass
    except TypeError:  # a leaf that cannot be hashed: worked out each time
        memo = None
    out = [_environment(), settings, name, repr(sorted(jit_options.items()))]
    _tree(treedef, out)
    for leaf in leaves:
        if eqx.is_array(leaf):
            out.append(_array_text(leaf))
        else:
            _value(leaf, out)
    key = hashlib.sha256("\n".join(out).encode()).hexdigest()
    if memo is not None:
        _KEYS[memo] = key
    return key


def _callable(exported, jit_options):
    return jax.jit(exported.call, **jit_options)


def _load(folder: Path, key: str, jit_options) -> tuple[bool, _Program | None]:
    """`(True, the program stored under key)`, `(True, None)` where `jax.export` refused
    it before, `(False, None)` where there is none or it does not read back (then it is
    traced and stored again)."""
    if (folder / f"{key}{_REFUSED}").exists():
        return True, None
    try:
        stored = _loads((folder / f"{key}{_SUFFIX}").read_bytes())
        if stored["key"] != key:
            return False, None
        exported = jax.export.deserialize(bytearray(stored["exported"]))
    except Exception:  # none, or a file from a crash or another version: trace it again
        return False, None
    program = _Program(_callable(exported, jit_options), stored["out_tree"], stored["out_static"])
    return True, program


def _trace(fun, folder, key, jit_options, leaves, treedef) -> _Program | None:
    """Trace `fun` for these arguments with `jax.export`, store it, and return it; None
    where `jax.export` refuses it (a host callback: equinox's `error_if` inside diffrax and
    optimistix), marked so, so that the calls run as `eqx.filter_jit`'s from then on."""
    positions = [i for i, x in enumerate(leaves) if eqx.is_array(x)]
    output = {}

    def flat(*arrays):
        filled = list(leaves)
        for i, x in zip(positions, arrays, strict=True):
            filled[i] = x
        args, kwargs = treedef.unflatten(filled)
        out_leaves, output["tree"] = jax.tree_util.tree_flatten(fun(*args, **kwargs))
        output["static"] = tuple(None if eqx.is_array(x) else (x,) for x in out_leaves)
        return [x for x in out_leaves if eqx.is_array(x)]

    shapes = [
        jax.ShapeDtypeStruct(
            np.shape(leaves[i]), leaves[i].dtype, weak_type=getattr(leaves[i], "weak_type", False)
        )
        for i in positions
    ]
    try:
        exported = jax.export.export(jax.jit(flat), disabled_checks=_lapack_checks())(*shapes)
        stored = {
            "key": key,
            "exported": exported.serialize(),
            "out_tree": output["tree"],
            "out_static": output["static"],
        }
        data = _dumps(stored)
        read_back = _loads(data)
    except Exception:  # refused by jax.export (a host callback) or not picklable
        _write(folder / f"{key}{_REFUSED}", b"")
        return None
    if read_back["out_tree"] != output["tree"]:
        _write(folder / f"{key}{_REFUSED}", b"")  # a structure that does not read back equal
        return None
    _write(folder / f"{key}{_SUFFIX}", data)
    return _Program(_callable(exported, jit_options), output["tree"], output["static"])


@functools.cache
def _lapack_checks() -> list:
    """`jax.export`'s compatibility checks of this jaxlib's LAPACK kernels, off: a stored
    program is read only by the jaxlib that wrote it (the key holds its version), and some
    (`lapack_dormqr_ffi`, optimistix's QR) carry no guarantee across versions."""
    try:
        from jaxlib import lapack

        names = [entry[0] for entry in lapack.registrations().get("cpu", [])]
    except Exception:  # another jaxlib: its programs with such a kernel stay in memory
        names = []
    return [jax.export.DisabledSafetyCheck.custom_call(name) for name in names]


def _write(path: Path, data: bytes) -> None:
    """Write `data` to `path` whole or not at all (a temporary file renamed; removed if
    the write stops, Ctrl-C included)."""
    try:
        handle, temporary = tempfile.mkstemp(dir=path.parent, suffix=".part")
    except OSError:
        return  # an unwritable cache is not worth failing for
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        os.replace(temporary, path)
    except OSError:
        pass
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)
