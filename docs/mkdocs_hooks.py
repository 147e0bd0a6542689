"""mkdocs hooks (mkdocs.yml `hooks:`): the README as the site's home page, the benchmarks' tables
as pages.

- `index.md` (a stub in docs/) is replaced by README.md with its links rewritten for the site:
  `docs/X` -> `X`, `benchmarks/X.md` stays (those pages are added below), a link to any other
  file of the repository (a script, an example) becomes its path as code, since the site does
  not carry it. A link to a file that does not exist is left as it is, so `mkdocs build
  --strict` fails on it.
- benchmarks/*.md are added to the site under `benchmarks/` (mkdocs.yml's nav lists them).
"""

import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent
_LINK = re.compile(r"(!?\[[^\]]*\])\(([^)\s]+)\)")


def on_files(files: Files, config) -> Files:
    for path in sorted((ROOT / "benchmarks").glob("*.md")):
        files.append(File.generated(config, f"benchmarks/{path.name}", abs_src_path=str(path)))
    return files


def _site_link(match: re.Match) -> str:
    text, target = match.groups()
    if re.match(r"^[a-z][a-z0-9+.-]*:|^#", target):  # a URL, mailto:, or an anchor
        return match.group(0)
    path, _, anchor = target.partition("#")
    path = posixpath.normpath(path)
    if path.startswith("docs/"):
        return f"{text}({path[len('docs/') :]}{'#' + anchor if anchor else ''})"
    if path.startswith("benchmarks/") and path.endswith(".md"):
        return match.group(0)
    if (ROOT / path).exists() and not text.startswith("!"):
        # a script or data file of the repository: the site does not carry it
        label = text[1:-1]
        return label if label.strip("`") == path else f"{label} (`{path}`)"
    return match.group(0)


def readme_for_site(readme: str) -> str:
    """README.md's text with its links rewritten for a page at the site's root."""
    out, fenced = [], False
    for line in readme.splitlines(keepends=True):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        out.append(line if fenced else _LINK.sub(_site_link, line))
    return "".join(out)


def on_page_markdown(markdown: str, page, config, files) -> str:
    if page.file.src_uri == "index.md":
        return readme_for_site((ROOT / "README.md").read_text(encoding="utf-8"))
    return markdown
