#!/usr/bin/env python3
"""Every relative link of README.md, CHANGELOG.md and docs/**/*.md names a
file (or folder) inside the repository, and every #anchor a heading of the
page it points into.

    check_links.py SOURCE_DIR
"""
import os
import re
import sys

LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s*\[[^\]]+\]:\s*(\S+)", re.M)
FENCE = re.compile(r"^(```|~~~).*?^\1", re.M | re.S)


def pages(root):
    for name in ("README.md", "CHANGELOG.md"):
        yield os.path.join(root, name)
    for folder, _, files in os.walk(os.path.join(root, "docs")):
        for name in sorted(files):
            if name.endswith(".md"):
                yield os.path.join(folder, name)


def anchors(page):
    """GitHub's anchors of a page's headings."""
    found, seen = set(), {}
    text = FENCE.sub("", open(page, encoding="utf-8").read())
    for match in re.finditer(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, re.M):
        slug = match.group(1).strip().lower()
        slug = re.sub(r"[^\w\- ]", "", slug).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        found.add(slug if count == 0 else f"{slug}-{count}")
    for match in re.finditer(r'<a\s+(?:name|id)="([^"]+)"', text):
        found.add(match.group(1))
    return found


def main():
    root = os.path.realpath(sys.argv[1])
    problems, count = [], 0
    for page in pages(root):
        if not os.path.exists(page):
            problems.append(f"{os.path.relpath(page, root)} is missing")
            continue
        text = FENCE.sub("", open(page, encoding="utf-8").read())
        text = re.sub(r"`[^`\n]*`", "", text)  # code spans are not links
        targets = LINK.findall(text) + REFERENCE.findall(text)
        for target in targets:
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                continue  # https:, mailto:, ...
            count += 1
            where = os.path.relpath(page, root)
            file, _, anchor = target.partition("#")
            resolved = os.path.realpath(os.path.join(os.path.dirname(page), file)) if file else page
            if not (resolved == root or resolved.startswith(root + os.sep)):
                problems.append(f"{where}: {target} leads out of the repository")
                continue
            if not os.path.exists(resolved):
                problems.append(f"{where}: {target} does not exist")
                continue
            if anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
                problems.append(f"{where}: {target}: no heading #{anchor}")
    for problem in problems:
        print(problem, file=sys.stderr)
    if problems:
        return 1
    print(f"{count} relative links resolve inside the repository")
    return 0


if __name__ == "__main__":
    sys.exit(main())
