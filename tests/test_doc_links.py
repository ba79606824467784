"""Every relative link of the shipped markdown (README, docs/, data/ and the rest, and the notebooks' markdown cells)
reaches a file that exists, and a ``#fragment`` into a markdown file names one of its headings as GitHub anchors
them: the front page links into long headings ("... (fixed 2026-11-27 before it ran)") that are edited as grids
land."""

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINK = re.compile(r"\]\(([^)\s]+)\)")
HEADING = re.compile(r"#{1,6}\s+(.*)")


def markdown_files() -> list[Path]:
    skip = {".venv", "runs", "node_modules"}
    return sorted(p for p in ROOT.rglob("*.md")
                  if not skip & set(p.relative_to(ROOT).parts)
                  and not any(part.startswith(".") for part in p.relative_to(ROOT).parts))


def anchors(path: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation but hyphens and underscores dropped, spaces to hyphens, a
    repeated anchor numbered -1, -2, ...; headings inside fenced code do not count."""
    found, seen, fenced = set(), {}, False
    for line in path.read_text().splitlines():
        if line.startswith("```"):
            fenced = not fenced
        match = None if fenced else HEADING.match(line)
        if match:
            slug = re.sub(r"[^\w\- ]", "", match.group(1).strip().lower()).replace(" ", "-")
            found.add(slug if slug not in seen else f"{slug}-{seen[slug]}")
            seen[slug] = seen.get(slug, 0) + 1
    return found


def markdown_of(path: Path) -> str:
    """A markdown file's text, or a notebook's markdown cells."""
    if path.suffix != ".ipynb":
        return path.read_text()
    cells = json.loads(path.read_text())["cells"]
    return "\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown")


def broken_links(path: Path) -> list[str]:
    broken = []
    for target in LINK.findall(markdown_of(path)):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto: ...
            continue
        file, _, fragment = target.partition("#")
        resolved = (path.parent / file) if file else path
        if not resolved.exists():
            broken.append(f"{target} (no such file)")
        elif fragment and resolved.suffix == ".md" and fragment not in anchors(resolved):
            broken.append(f"{target} (no such heading)")
    return broken


def test_the_shipped_markdown_is_found():
    names = {p.relative_to(ROOT).as_posix() for p in markdown_files()}
    assert {"README.md", "docs/corrector.md", "docs/cli.md"} <= names


def test_every_relative_link_reaches_its_file_and_heading():
    pages = markdown_files() + sorted((ROOT / "notebooks").glob("*.ipynb"))
    broken = {p.relative_to(ROOT).as_posix(): b for p in pages if (b := broken_links(p))}
    assert broken == {}


def test_a_broken_link_and_a_wrong_heading_are_caught(tmp_path):
    (tmp_path / "other.md").write_text("# Where it stands (fixed 2026-12-07)\n\n"
                                       "```\n# not a heading\n```\n## A\n## A\n")
    page = tmp_path / "page.md"
    page.write_text("[ok](other.md#where-it-stands-fixed-2026-12-07) [ok](other.md#a-1) [web](https://x.org/y)\n"
                    "[gone](missing.md) [wrong](other.md#not-a-heading) [self](#nothing-here)\n")
    assert broken_links(page) == ["missing.md (no such file)", "other.md#not-a-heading (no such heading)",
                                  "#nothing-here (no such heading)"]


def test_a_notebooks_links_are_its_markdown_cells(tmp_path):
    cells = [{"cell_type": "markdown", "source": ["[gone](gone.md) ", "[ok](nb.ipynb)"]},
             {"cell_type": "code", "source": ["x = '[code](not-a-link.md)'"]}]
    notebook = tmp_path / "nb.ipynb"
    notebook.write_text(json.dumps({"cells": cells}))
    assert broken_links(notebook) == ["gone.md (no such file)"]
