#!/usr/bin/env python3
"""Every property gst-inspect-1.0 shows for each wircam element is in that
element's section of docs/elements.md, and every property documented there
exists; the pad templates' names too.

    check_elements.py BUILD_DIR docs/elements.md

GST_PLUGIN_PATH is set to BUILD_DIR/gst-plugins and the registry is a
private one in a temporary folder.
"""
import os
import re
import subprocess
import sys
import tempfile

ELEMENTS = ["wircsrc", "wircdepay", "wirccontrol", "marvelmindpositions",
            "tjpegdec", "apriltagdetect", "tagoverlay"]


def inspect(element, env):
    text = subprocess.run(["gst-inspect-1.0", element], capture_output=True, text=True,
                          env=env, timeout=60).stdout
    if "Element Properties:" not in text:
        raise SystemExit(f"gst-inspect-1.0 {element} shows no properties:\n{text}")
    properties, pads, section = set(), set(), None
    for line in text.splitlines():
        if line and not line.startswith(" "):
            section = line.rstrip(":")
            continue
        if section == "Element Properties":
            match = re.match(r"^  ([a-z][a-z0-9-]*)\s*:", line)
            if match:
                properties.add(match.group(1))
        elif section == "Pad Templates":
            match = re.match(r"^  (SINK|SRC) template: '([^']+)'", line)
            if match:
                pads.add(match.group(2))
    return properties, pads


def documented(page):
    """{element: (properties, pads)} from the page's '## element' sections:
    the first column of each table row whose header names 'property' or
    'pad'."""
    sections, current, kind = {}, None, None
    for line in open(page, encoding="utf-8"):
        heading = re.match(r"^## `?([a-z]+)`?\s*$", line)
        if heading:
            current = heading.group(1) if heading.group(1) in ELEMENTS else None
            if current:
                sections.setdefault(current, (set(), set()))
            kind = None
            continue
        if not current or not line.startswith("|"):
            kind = None if not line.startswith("|") else kind
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[0] in ("property", "pad"):
            kind = cells[0]
            continue
        if kind is None or set(cells[0]) <= set("-"):
            continue
        name = re.fullmatch(r"`([^`]+)`", cells[0])
        if name:
            sections[current][0 if kind == "property" else 1].add(name.group(1))
    return sections


def main():
    build, page = sys.argv[1], sys.argv[2]
    env = dict(os.environ)
    env["GST_PLUGIN_PATH"] = os.path.join(os.path.abspath(build), "gst-plugins")
    problems = []
    with tempfile.TemporaryDirectory() as scratch:
        env["GST_REGISTRY"] = os.path.join(scratch, "registry.bin")
        docs = documented(page)
        for element in ELEMENTS:
            shown_properties, shown_pads = inspect(element, env)
            doc_properties, doc_pads = docs.get(element, (set(), set()))
            if element not in docs:
                problems.append(f"{page}: no section '## {element}'")
            for name in sorted(shown_properties - doc_properties):
                problems.append(f"{page}: {element} property '{name}' is not documented")
            for name in sorted(doc_properties - shown_properties):
                problems.append(f"{page}: {element} property '{name}' does not exist")
            for name in sorted(shown_pads ^ doc_pads):
                problems.append(f"{page}: {element} pad template '{name}' differs")
    for problem in problems:
        print(problem, file=sys.stderr)
    if problems:
        return 1
    print(f"{len(ELEMENTS)} elements: gst-inspect-1.0 and {page} agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
