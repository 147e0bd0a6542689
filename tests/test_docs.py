"""The documentation site (mkdocs.yml): every public name has its API reference entry, and the
site builds with warnings as errors.

`.ci/run` builds the site itself (`mkdocs build --strict`), which is the gate; the slow test
here runs the same build for a developer who installed the `docs` extra.
"""

import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import jaximpact

ROOT = Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api"
# `::: jaximpact._module.name` and the `heading: jaximpact.name` it is shown under
_DIRECTIVE = re.compile(r"^::: (jaximpact\.[\w.]+)\n    options:\n((?:      .*\n)*)", re.M)


def _directives():
    found = {}
    for page in sorted(API.glob("*.md")):
        for match in _DIRECTIVE.finditer(page.read_text(encoding="utf-8")):
            heading = re.search(r"^      heading: (\S+)$", match.group(2), re.M)
            found[match.group(1)] = (page.name, heading.group(1) if heading else None)
    return found


def test_every_public_name_has_an_api_entry():
    """Each name of `jaximpact.__all__` is documented once, where it is defined, under its
    public name; a name added to the package without an entry fails here."""
    directives = _directives()
    documented = {}
    for path, (page, heading) in directives.items():
        if heading is None or not heading.startswith("jaximpact."):
            continue
        name = heading[len("jaximpact.") :]
        assert name not in documented, f"{name} documented twice ({documented[name]}, {page})"
        documented[name] = page
        module, _, attr = path.rpartition(".")
        if name in jaximpact.__all__ and isinstance(getattr(jaximpact, name), type(jaximpact)):
            assert path == f"jaximpact.{name}", (page, path)
            continue
        assert attr == name, f"{page}: {path} shown as {heading}"
        defining = importlib.import_module(module)
        assert getattr(defining, attr) is getattr(jaximpact, name), (page, path)
    missing = sorted(set(jaximpact.__all__) - set(documented))
    assert not missing, f"public names with no entry in docs/api/*.md: {missing}"


def test_closed_forms_page_lists_the_module():
    """docs/api/closed_forms.md names each public function of `jaximpact.closed_forms`
    (mkdocstrings does not list a module's re-exported names by itself)."""
    text = (API / "closed_forms.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^        - (\w+)$", text, re.M))
    public = {
        name
        for name, value in vars(jaximpact.closed_forms).items()
        if not name.startswith("_") and callable(value)
    }
    assert listed == public


def test_every_page_is_in_the_nav():
    """Each page of docs/ and each table of benchmarks/ is listed in mkdocs.yml's nav: the strict
    build refuses a page left out of it, and that build runs only in the slow group."""
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8").split("\nnav:", 1)[1]
    listed = set(re.findall(r"(?:: |- )(\S+\.md)$", nav, re.M))
    pages = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    pages |= {f"benchmarks/{p.name}" for p in (ROOT / "benchmarks").glob("*.md")}
    missing = sorted(pages - listed)
    assert not missing, f"pages not in mkdocs.yml's nav: {missing}"


@pytest.mark.slow
def test_site_builds_strict(tmp_path):
    missing = [
        module
        for module in ("mkdocs", "mkdocstrings", "mkdocstrings_handlers.python", "material")
        if importlib.util.find_spec(module.split(".")[0]) is None
        or (module.count(".") and importlib.util.find_spec(module) is None)
    ]
    if missing:
        pytest.skip(f'{", ".join(missing)} not installed: pip install -e ".[docs]"')
    completed = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        timeout=600,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    page = (tmp_path / "api" / "impact" / "index.html").read_text(encoding="utf-8")
    assert "One impact of a body of mass" in page  # the docstring, rendered
    assert (tmp_path / "index.html").read_text(encoding="utf-8").count("jaximpact") > 10
