#!/usr/bin/env python3
"""Every option wirc-recorder --help lists is in docs/recorder.md's option
tables, and every option those tables name exists in --help.

    check_recorder_options.py BUILD/bin/wirc-recorder docs/recorder.md
"""
import re
import subprocess
import sys

OPTION = re.compile(r"--[a-z0-9][a-z0-9-]*")


def help_options(binary):
    text = subprocess.run([binary, "--help"], capture_output=True, text=True,
                          timeout=30, check=True).stdout
    options = set()
    for line in text.splitlines():
        # An option line starts two spaces in; its spec ends at the first
        # run of two spaces (the description after it names other options).
        match = re.match(r"^  (-h, )?(--\S.*)$", line)
        if not match:
            continue
        spec = re.split(r"\s{2,}", match.group(2))[0]
        options.update(OPTION.findall(spec))
        if match.group(1):
            options.add("-h")
    return options


def documented_options(page):
    options = set()
    in_options = False
    for line in open(page, encoding="utf-8"):
        if line.startswith("## "):
            in_options = line.strip() == "## Options"
            continue
        if not in_options or not line.startswith("| "):
            continue
        first = line.split("|")[1]
        if set(first.strip()) <= set("-"):
            continue  # the header's separator
        options.update(OPTION.findall(first))
        if re.search(r"`-h`", first):
            options.add("-h")
    return options


def main():
    binary, page = sys.argv[1], sys.argv[2]
    given = help_options(binary)
    documented = documented_options(page)
    if not given:
        print(f"no options found in {binary} --help", file=sys.stderr)
        return 1
    missing = sorted(given - documented)
    extra = sorted(documented - given)
    for option in missing:
        print(f"{page}: {option} is in --help but not documented", file=sys.stderr)
    for option in extra:
        print(f"{page}: {option} is documented but not in --help", file=sys.stderr)
    if missing or extra:
        return 1
    print(f"{len(given)} options: --help and {page} agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
