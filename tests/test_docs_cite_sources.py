"""The repository cites each fact by its own source (a paper, a vendor's page, a connector's repository and file, a
data set's name, or the project's own measurement), never by the team's notes file outside the repository, which a
reader of the repository cannot open."""

from __future__ import annotations

from pathlib import Path

from tests.test_imports import virtual_environments

ROOT = Path(__file__).resolve().parents[1]
SKIPPED_FOLDERS = {".git", "build", "dist", ".venv", "__pycache__", ".pytest_cache", ".hypothesis", "runs", "out"}
"""Folders that are not the repository's own files (build outputs, caches, .gitignore's entries)."""
ALLOWED: set[tuple[str, str]] = set()
"""(path, stripped line) pairs that may name the notes file: code that opens the notes file in ../shared by path on
purpose. There is none today; add such a line here, with a comment saying why, rather than widen the check."""
NOTES_FILE, NOTES_SECTION = "NOTES" + ".md", "NOTES" + " §"
"""Spelt in two parts so that this file does not name them itself."""


def repository_files() -> list[Path]:
    """Every Markdown and Python file of the repository, outside SKIPPED_FOLDERS and egg-info folders."""
    found, skipped = [], SKIPPED_FOLDERS | virtual_environments()
    for path in ROOT.rglob("*"):
        parts = path.relative_to(ROOT).parts
        if any(part in skipped or part.endswith(".egg-info") for part in parts[:-1]):
            continue
        if path.suffix in (".md", ".py") and path.is_file():
            found.append(path)
    return found


def notes_citations(path: Path, root: Path = ROOT) -> list[str]:
    """'path:line: text' for each line of `path` that names the notes file or one of its sections."""
    relative = str(path.relative_to(root))
    return [
        f"{relative}:{number}: {line.strip()}"
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if (NOTES_FILE in line or NOTES_SECTION in line) and (relative, line.strip()) not in ALLOWED
    ]


def test_a_citation_of_the_notes_file_is_found(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(f"A fact ({NOTES_FILE} §8).\nAnother ({NOTES_SECTION}9).\nA fact (Penner 2002).\n")
    assert notes_citations(page, tmp_path) == [
        f"page.md:1: A fact ({NOTES_FILE} §8).",
        f"page.md:2: Another ({NOTES_SECTION}9).",
    ]


def test_no_file_of_the_repository_cites_the_notes_file():
    files = repository_files()
    assert any(path.name == "README.md" for path in files) and Path(__file__).resolve() in files
    found = [citation for path in files for citation in notes_citations(path)]
    assert not found, "cite the fact's own source instead of the notes file:\n" + "\n".join(found)
