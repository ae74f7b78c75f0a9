"""The README stays readable (issue 44, item 7): no sentence of its prose runs past MAX_SENTENCE_WORDS words and no
table cell past MAX_CELL_WORDS. Prose is every line outside fenced code blocks and tables, headings and images; a
word is a run of non-space characters, inside inline code and links alike (a link counts its text only). Long
explanations and big tables belong in docs/*.md, which the README links to.

`python3 tests/test_readme_style.py [FILE]` prints the counts this test checks."""

from __future__ import annotations

import re
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_SENTENCE_WORDS = 35
MAX_CELL_WORDS = 30
ABBREVIATIONS = ("e.g.", "i.e.", "vs.", "etc.", "cf.", "approx.", "no.", "eq.", "fig.")
"""Words ending in a full stop that do not end a sentence."""
CODE_SPAN = re.compile(r"`[^`]*`")
LINK = re.compile(r"!?\[([^\]]*)\]\([^)]*\)")
LIST_ITEM = re.compile(r"^\s*(?:[-*+]|\d+[.)])\s+")
SENTENCE_END = re.compile(r"(?<=[.!?])[)\"'*]*\s+")


def blocks(text: str) -> tuple[list[str], list[str]]:
    """(prose units, table rows) of a Markdown text: a prose unit is a paragraph or one list item, its lines joined;
    fenced code, headings and image lines are left out."""
    units, rows, current, fenced = [], [], [], False

    def close():
        if current:
            units.append(" ".join(current))
            current.clear()

    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("```"):
            close()
            fenced = not fenced
        elif fenced:
            continue
        elif stripped.startswith("|"):
            close()
            rows.append(stripped)
        elif not stripped or stripped.startswith("#") or re.fullmatch(r"!\[[^\]]*\]\([^)]*\)", stripped):
            close()
        else:
            if LIST_ITEM.match(line):
                close()
                stripped = LIST_ITEM.sub("", line).strip()
            current.append(stripped.lstrip("> "))
    close()
    return units, rows


def words(text: str) -> int:
    """Words in `text`: a link counts its text, inline code its own words."""
    return len(LINK.sub(r"\1", text).replace("`", " ").split())


def sentences(unit: str) -> list[str]:
    """The sentences of one prose unit, split after a full stop, question or exclamation mark followed by a space
    (not inside inline code, not after an abbreviation)."""
    spans: list[str] = []

    def hold(match: re.Match) -> str:
        spans.append(match.group(0))
        return f"\x00{len(spans) - 1}\x00"

    held = CODE_SPAN.sub(hold, unit)
    pieces, start = [], 0
    for end in SENTENCE_END.finditer(held):
        before = held[start:end.start()].split()
        if before and before[-1].lower().strip("(*") in ABBREVIATIONS:
            continue
        pieces.append(held[start:end.start()])
        start = end.end()
    pieces.append(held[start:])
    restore = re.compile("\x00(\\d+)\x00")
    return [restore.sub(lambda m: spans[int(m.group(1))], piece).strip() for piece in pieces if piece.strip()]


def cells(row: str) -> list[str]:
    """The cells of one table row (an escaped `\\|` stays inside its cell); none for the separator row."""
    inner = row.strip().strip("|")
    if re.fullmatch(r"[\s:|-]*", inner):
        return []
    return [cell.replace("\\|", "|").strip() for cell in re.split(r"(?<!\\)\|", inner)]


def counts(text: str) -> tuple[list[tuple[int, str]], list[tuple[int, str]]]:
    """(words, sentence) for every prose sentence and (words, cell) for every table cell of `text`."""
    units, rows = blocks(text)
    found = [(words(sentence), sentence) for unit in units for sentence in sentences(unit)]
    table = [(words(cell), cell) for row in rows for cell in cells(row)]
    return found, table


def test_sentences_are_split_where_they_end_and_not_inside_code():
    unit = "Run `a. b` now, e.g. here. Then (a second one). Third? Yes."
    assert sentences(unit) == ["Run `a. b` now, e.g. here.", "Then (a second one).", "Third?", "Yes."]


def test_prose_leaves_out_code_tables_and_headings_and_counts_link_text():
    text = "# Title words\n\nOne two\nthree [four five](docs/x.md).\n\n```bash\nnot prose at all\n```\n- item one\n" \
           "- item two\n\n| a b | c `d\\|e` |\n|---|---|\n"
    found, table = counts(text)
    assert [n for n, _ in found] == [5, 2, 2]
    assert [n for n, _ in table] == [2, 2]


def test_no_readme_sentence_or_table_cell_is_too_long():
    found, table = counts((ROOT / "README.md").read_text(encoding="utf-8"))
    assert found and table
    long_sentences = [f"{n} words: {sentence}" for n, sentence in found if n > MAX_SENTENCE_WORDS]
    long_cells = [f"{n} words: {cell}" for n, cell in table if n > MAX_CELL_WORDS]
    assert not long_sentences, f"README sentences over {MAX_SENTENCE_WORDS} words:\n" + "\n".join(long_sentences)
    assert not long_cells, f"README table cells over {MAX_CELL_WORDS} words:\n" + "\n".join(long_cells)


if __name__ == "__main__":
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "README.md"
    text = path.read_text(encoding="utf-8")
    found, table = counts(text)
    lengths = [n for n, _ in found]
    print(f"{path}: {len(text.splitlines())} lines; {len(lengths)} sentences, mean {statistics.mean(lengths):.1f} "
          f"words, median {statistics.median(lengths)}, max {max(lengths)}, over {MAX_SENTENCE_WORDS}: "
          f"{sum(n > MAX_SENTENCE_WORDS for n in lengths)}; {len(table)} table cells, max "
          f"{max(n for n, _ in table)} words, over {MAX_CELL_WORDS}: {sum(n > MAX_CELL_WORDS for n, _ in table)}")
