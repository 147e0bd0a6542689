"""The package's layout holds: every unit imports only the layers below it, and no module
outside the laws decides anything by a law's name (a law's facts live in its row of the law
table, `jaximpact._laws.table`)."""

import ast
from pathlib import Path

import pytest

import jaximpact as ji

PACKAGE = Path(ji.__file__).parent

# bottom to top; a unit may import only units of a lower rank
RANK = {
    **dict.fromkeys(("_status", "_checks", "_powers", "_progress", "_cache"), 0),
    **dict.fromkeys(("_files", "_interrupt", "_choices", "_xla_log", "_least_squares"), 0),
    **dict.fromkeys(("_tracing", "_stored", "_lazy"), 0),
    **dict.fromkeys(("_version", "_plotting", "_format", "_compiling"), 1),
    "_laws": 2,
    **dict.fromkeys(("_curves", "closed_forms"), 3),
    "_solve": 4,
    **dict.fromkeys(("_fit", "_batch", "_oblique"), 5),
    **dict.fromkeys(("_studies", "_jobs", "_posterior"), 6),
    **dict.fromkeys(("_paper", "_bench", "_engines"), 7),
    "_cli": 8,
    "__init__": 9,
}
# the scipy reference that checks the library: written as a scipy user writes each law, on
# purpose apart from the law table
NAME_CHECKS_ALLOWED = ("_laws", "_bench")


def _unit(path: Path) -> str:
    rel = path.relative_to(PACKAGE)
    return rel.parts[0].removesuffix(".py")


def _imports(path: Path):
    """The units that `path` imports relatively (`from .x import`, `from .. import y`)."""
    parts = list(path.relative_to(PACKAGE).parts[:-1])
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = parts[: len(parts) - (node.level - 1)]
            target = base + (node.module.split(".") if node.module else [])
            if target:
                yield target[0]
            else:  # `from .. import name`: a unit if it names one, else the package's names
                for alias in node.names:
                    yield alias.name if alias.name in RANK else "__init__"


MODULES = sorted(PACKAGE.rglob("*.py"))


def test_every_unit_has_a_rank():
    assert {_unit(p) for p in MODULES} <= set(RANK)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_go_down_the_layers(path):
    unit = _unit(path)
    upward = sorted({t for t in _imports(path) if t != unit and RANK.get(t, -1) >= RANK[unit]})
    assert not upward, f"{unit} imports {upward}, which are not below it"


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_law_name_comparisons_outside_the_laws(path):
    if _unit(path) in NAME_CHECKS_ALLOWED:
        return
    names = set(ji.LAW_NAMES)
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare):
            for side in [node.left, *node.comparators]:
                values = side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set)) else [side]
                found += [
                    f"line {node.lineno}: {v.value!r}"
                    for v in values
                    if isinstance(v, ast.Constant) and v.value in names
                ]
    assert not found, f"law names compared outside the law table: {found}"


FORMATTED = ("jaximpact", "tests", "benchmarks", "examples", "docs")


def test_ruff_formats_the_code():
    """ruff's formatter decides the layout (pyproject.toml's [tool.ruff]), with no `fmt: skip`."""
    pytest.importorskip("ruff")
    import subprocess
    import sys

    root = PACKAGE.parent
    checked = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--check", *FORMATTED],
        cwd=root,
        capture_output=True,
        text=True,
    )
    assert checked.returncode == 0, checked.stdout + checked.stderr
    marker = "# fmt" + ": skip"
    skips = [p for d in FORMATTED for p in (root / d).rglob("*.py") if marker in p.read_text()]
    assert not skips, f"{marker} in {skips}: let ruff format decide"
