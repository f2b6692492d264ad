#!/usr/bin/env python3
"""Checks the relative links of README.md and docs/*.md, offline.

Every link or image whose target is not a URL must name a file or folder that exists, and a
`#anchor` (alone, or after a Markdown file) must name a heading of that file, spelled as GitHub
spells heading anchors. Links inside code blocks and code spans are not links and are skipped.
Prints each broken link as `file:line: target: why` and exits 1 if there is any; exits 0
otherwise. Usage: .ci/check-links.py [FILE.md ...] (by default README.md and docs/*.md, from the
repository's root).
"""

import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
# [text](target "title") and ![alt](target); the text may hold one level of brackets.
INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
HTML_ID = re.compile(r"""<a\s+(?:name|id)=["']([^"']+)["']""", re.IGNORECASE)
URL = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def shown(path: Path) -> str:
    """The path as the messages show it: relative to the current folder."""
    return os.path.relpath(path)


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: its text, lower-cased, without punctuation, spaces as '-'."""
    text = CODE_SPAN.sub(lambda m: m.group(2), heading)
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link's text only
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = text.replace("*", "")
    text = text.strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in "-_ ")
    return text.replace(" ", "-")


def lines_outside_code(path: Path):
    """Yields (line number, line) for each line outside fenced code blocks."""
    fence = None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = FENCE.match(line)
        if m:
            if fence is None:
                fence = m.group(1)
            elif m.group(1) == fence:
                fence = None
            continue
        if fence is None:
            yield number, line


def anchors(path: Path, cache: dict) -> set:
    if path not in cache:
        found, seen = set(), {}
        for _, line in lines_outside_code(path):
            m = HEADING.match(line)
            if m:
                base = slug(m.group(2))
                n = seen.get(base, 0)
                seen[base] = n + 1
                found.add(base if n == 0 else f"{base}-{n}")
            found.update(HTML_ID.findall(line))
        cache[path] = found
    return cache[path]


def check(path: Path, cache: dict) -> list:
    problems = []
    for number, line in lines_outside_code(path):
        bare = CODE_SPAN.sub("", line)
        targets = INLINE.findall(bare)
        m = REFERENCE.match(bare)
        if m:
            targets.append(m.group(1))
        for target in targets:
            if not target or URL.match(target):
                continue
            file_part, _, anchor = target.partition("#")
            dest = (path.parent / file_part).resolve() if file_part else path
            where = f"{shown(path)}:{number}: {target}"
            if not dest.exists():
                problems.append(f"{where}: no such file or folder")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest, cache):
                problems.append(f"{where}: no heading with anchor #{anchor} in {shown(dest)}")
    return problems


def main(argv: list) -> int:
    files = [Path(a).resolve() for a in argv] or [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    cache, problems = {}, []
    for path in files:
        if not path.is_file():
            problems.append(f"{path}: no such file")
            continue
        problems += check(path, cache)
    for problem in problems:
        print(problem)
    if problems:
        print(f"{len(problems)} broken link(s)", file=sys.stderr)
        return 1
    print(f"links: {len(files)} files checked, none broken")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
