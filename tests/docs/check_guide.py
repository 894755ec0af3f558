#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Checks the user guide in docs/guide/ against the repository and the built command-line tool.

    check_guide.py <repo root> <path to hexatwist binary>

(a) LICENSE and CHANGELOG.md exist at the root, and every relative Markdown link in
    docs/guide/*.md and CHANGELOG.md resolves to an existing file (the anchor after '#' is
    ignored; links with a scheme, such as https:, and links inside code are not checked);
(b) every command `hexatwist <subcommand> ... --option ...` in an inline code span or a fenced
    block of docs/guide/*.md names a subcommand that exists and options that its `--help` lists.
    `<binary> <subcommand> --help` runs once per subcommand. In a fenced block that has lines
    starting with "$ " (a terminal transcript) only those lines are commands; in other blocks every
    line is. Blocks in yaml, python, C, C++, CMake, JSON and INI are skipped. A command is found
    after a shell operator too (`a && hexatwist ik ...`, `... | hexatwist stream ...`). Inline
    code and link text may run over a line break; a placeholder subcommand (`hexatwist <command>`)
    is not checked.

Exit 0 when everything holds; 1 with one line per problem ("file:line: ..."); 2 for bad usage.
Standard library only.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

SKIPPED_LANGUAGES = {"yaml", "yml", "python", "py", "c", "cpp", "c++", "cmake", "json", "ini"}
SHELL_OPERATORS = {"|", "||", "&", "&&", ";", ";;", "(", ")", "<", ">", ">>", "<<", "2>", "&>"}
SUBCOMMAND = re.compile(r"^[a-z][a-z0-9-]*$")
LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(\s*(<[^>]*>|[^)\s]*)(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*(\S+)")
FENCE = re.compile(r"^\s{0,3}(`{3,}|~{3,})\s*([^`\s]*)")
INLINE_CODE = re.compile(r"(`+)(.+?)(?<!`)\1(?!`)")


def markdown_lines(text: str):
    """Yields (line number, line, kind) for every line: kind is "fence" for a fence line, the
    block's language ("" if none) for a line inside a fenced block, and None outside."""
    fence = None
    language = None
    for number, line in enumerate(text.splitlines(), start=1):
        m = FENCE.match(line)
        if fence is None and m:
            fence, language = m.group(1), m.group(2).lower()
            yield number, line, "fence"
            continue
        if fence is not None and line.strip().startswith(fence[0] * len(fence)) and \
                line.strip().strip(fence[0]) == "":
            fence, language = None, None
            yield number, line, "fence"
            continue
        yield number, line, language


def strip_inline_code(line: str) -> str:
    """The text with its inline code spans blanked out (a link inside code is not a link)."""
    return INLINE_CODE.sub(lambda m: " " * len(m.group(0)), line)


def paragraphs(text: str):
    """Yields [(line number, line)] for every paragraph outside fenced blocks."""
    paragraph: list[tuple[int, str]] = []
    for number, line, language in markdown_lines(text):
        if language is None and line.strip():
            paragraph.append((number, line))
            continue
        if paragraph:
            yield paragraph
        paragraph = []
    if paragraph:
        yield paragraph


def check_links(root: Path, path: Path, problems: list[str]) -> None:
    """Every relative link of a page (its text may run over a line break) names an existing file."""
    text = path.read_text(encoding="utf-8")
    for paragraph in paragraphs(text):
        found = []
        for number, line in paragraph:
            ref = REFERENCE.match(strip_inline_code(line))
            if ref:
                found.append((number, ref.group(1)))
        joined, starts = "", []
        for number, line in paragraph:
            starts.append((len(joined), number))
            joined += line + " "
        prose = strip_inline_code(joined)
        for m in LINK.finditer(prose):
            found.append((max(n for offset, n in starts if offset <= m.start()), m.group(1)))
        for number, target in found:
            target = target.strip("<>")
            if not target or target.startswith("#") or re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                continue
            file_part = target.split("#", 1)[0].split("?", 1)[0]
            resolved = (path.parent / file_part).resolve()
            if not resolved.is_file():
                problems.append(f"{path.relative_to(root)}:{number}: link '{target}' does not resolve to a file")


def tokens_of(command: str) -> list[str]:
    """Shell words and operators of one command line; quotes removed, comments dropped. A command
    substitution (`...` or $(...)) starts a command of its own."""
    command = command.replace("$(", " ; ").replace("`", " ; ")
    lexer = shlex.shlex(command, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    lexer.commenters = "#"
    try:
        return list(lexer)
    except ValueError:  # an unbalanced quote: fall back to words
        return command.split()


def hexatwist_invocations(command: str):
    """Yields (subcommand or None, [options]) for every `hexatwist ...` segment of a command line."""
    words = tokens_of(command)
    segment: list[str] = []
    segments = []
    for w in words:
        if w in SHELL_OPERATORS or (w and set(w) <= set("|&;<>()")):
            segments.append(segment)
            segment = []
        else:
            segment.append(w)
    segments.append(segment)
    for seg in segments:
        # Leading environment assignments (NAME=value) are not the program.
        while seg and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", seg[0]):
            seg = seg[1:]
        if not seg or os.path.basename(seg[0]) != "hexatwist":
            continue
        rest = seg[1:]
        sub = None
        if rest and not rest[0].startswith("-"):
            if not SUBCOMMAND.match(rest[0]):
                continue  # a placeholder such as <command> or ...
            sub, rest = rest[0], rest[1:]
        options = [w.split("=", 1)[0] for w in rest if w.startswith("--") and len(w) > 2]
        yield sub, options


def commands_in(path: Path):
    """Yields (line number, command text) for every candidate command line of a guide page."""
    text = path.read_text(encoding="utf-8")
    lines = list(markdown_lines(text))
    block: list[tuple[int, str]] = []
    paragraph: list[tuple[int, str]] = []
    block_language = None
    for number, line, language in lines:
        if language == "fence":
            yield from inline_commands(paragraph)
            paragraph = []
            if block_language is None:
                block = []
                m = FENCE.match(line)
                block_language = m.group(2).lower() if m else ""
            else:
                yield from block_commands(block, block_language)
                block_language = None
            continue
        if block_language is not None:
            block.append((number, line))
            continue
        # Inline code may run over a line break: a paragraph is searched as one text.
        if line.strip():
            paragraph.append((number, line))
            continue
        yield from inline_commands(paragraph)
        paragraph = []
    yield from inline_commands(paragraph)


def inline_commands(paragraph: list[tuple[int, str]]):
    """Yields (line number, code) for every inline code span of a paragraph."""
    text = ""
    starts = []
    for number, line in paragraph:
        starts.append((len(text), number))
        text += line + " "
    for m in INLINE_CODE.finditer(text):
        number = max(n for offset, n in starts if offset <= m.start())
        code = m.group(2).strip()
        if code.startswith("$ "):
            code = code[2:]
        yield number, code


def block_commands(block: list[tuple[int, str]], language: str):
    if language in SKIPPED_LANGUAGES:
        return
    transcript = any(line.lstrip().startswith("$ ") for _, line in block)
    pending = None
    for number, line in block:
        stripped = line.strip()
        if transcript:
            if pending is None and not stripped.startswith("$ "):
                continue
            if pending is None:
                stripped = stripped[2:]
        if pending is not None:
            pending = (pending[0], pending[1] + " " + stripped)
        else:
            pending = (number, stripped)
        if pending[1].endswith("\\"):
            pending = (pending[0], pending[1][:-1])
            continue
        yield pending
        pending = None
    if pending is not None:
        yield pending


def parse_help(text: str) -> tuple[set[str], set[str]]:
    """The long options and the subcommands a CLI11 help text lists."""
    options: set[str] = set()
    subcommands: set[str] = set()
    section = ""
    for line in text.splitlines():
        if re.match(r"^\S.*:\s*$", line):  # a section header: "Options:", "Subcommands:"
            section = line.strip().lower()
            continue
        # An entry starts at a small indent with its names ("-h,--help", "--pose TEXT", "ik");
        # descriptions continued on further lines are indented far deeper.
        m = re.match(r"^ {1,6}(\S+)", line)
        if not m:
            continue
        if section.startswith("options") and m.group(1).startswith("-"):
            for name in m.group(1).split(","):
                if name.startswith("--"):
                    options.add(name.split("=", 1)[0])
        elif section.startswith("subcommands"):
            subcommands.add(m.group(1))
    return options, subcommands


def run_help(binary: str, sub: str | None) -> str | None:
    """`<binary> [sub] --help`'s output, or None if it fails."""
    argv = [binary] + ([sub] if sub else []) + ["--help"]
    try:
        run = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        print(f"check_guide: cannot run {' '.join(argv)}: {e}", file=sys.stderr)
        return None
    return run.stdout if run.returncode == 0 else None


def help_options(binary: str, sub: str | None, cache: dict) -> set[str] | None:
    """The long options `--help` lists for a subcommand (None: the root); None if there is no such
    subcommand. Each help text is read once."""
    if sub in cache:
        return cache[sub]
    if None not in cache:
        text = run_help(binary, None)
        cache[None] = parse_help(text)[0] if text is not None else None
        cache["<subcommands>"] = parse_help(text)[1] if text is not None else set()
    if sub is not None:
        # CLI11 answers `hexatwist nonsense --help` with the root's help: the root's list decides.
        text = run_help(binary, sub) if sub in cache["<subcommands>"] else None
        cache[sub] = parse_help(text)[0] if text is not None else None
    return cache[sub]


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print("usage: check_guide.py <repo root> <path to hexatwist binary>", file=sys.stderr)
        return 2
    root = Path(argv[1]).resolve()
    binary = argv[2]
    problems: list[str] = []
    guide = root / "docs" / "guide"
    pages = sorted(guide.glob("*.md"))
    if not pages:
        problems.append(f"{guide}: no Markdown pages")
    for name in ("LICENSE", "CHANGELOG.md"):
        if not (root / name).is_file():
            problems.append(f"{name}: missing at the repository root")
    if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
        problems.append(f"{binary}: not an executable file")
        binary = None

    for page in pages + [p for p in [root / "CHANGELOG.md"] if p.is_file()]:
        check_links(root, page, problems)

    cache: dict = {}
    for page in pages:
        for number, command in commands_in(page):
            for sub, options in hexatwist_invocations(command):
                where = f"{page.relative_to(root)}:{number}"
                if binary is None:
                    continue
                known = help_options(binary, sub, cache)
                if known is None:
                    problems.append(f"{where}: 'hexatwist {sub}': no such subcommand")
                    continue
                for option in options:
                    if option not in known:
                        name = f"hexatwist {sub}" if sub else "hexatwist"
                        problems.append(f"{where}: '{name}' has no option {option}")

    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
