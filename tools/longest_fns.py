#!/usr/bin/env python3
"""The longest functions of a Rust source tree, by lines from `fn` to its closing brace.

Usage: longest_fns.py DIR [N]   (default N = 15; test modules after `#[cfg(test)] mod` are skipped)

Braces are matched on the text with string and char literals and comments removed, so the
count is exact for ordinary code; it is a size to compare between two trees, not a parser.
"""
import os
import re
import sys

FN = re.compile(r"^\s*(pub(\([^)]*\))?\s+)?(const\s+|async\s+|unsafe\s+)*fn\s+(\w+)")


def strip(line):
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    return re.sub(r"//.*", "", line)


def functions(path):
    lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
    out = []
    for i, line in enumerate(lines):
        if re.match(r"\s*#\[cfg\(test\)\]", line) and i + 1 < len(lines) and re.match(
            r"\s*(pub\s+)?mod\s+\w+", lines[i + 1]
        ):
            break
        m = FN.match(line)
        if not m:
            continue
        depth, opened = 0, False
        for k in range(i, len(lines)):
            text = strip(lines[k])
            if not opened and ";" in text and "{" not in text:
                break  # a declaration without a body (trait item)
            depth += text.count("{") - text.count("}")
            opened = opened or "{" in text
            if opened and depth <= 0:
                out.append((k - i + 1, f"{path}:{i + 1}", m.group(4)))
                break
    return out


def main():
    root = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 15
    found = []
    for d, _, files in os.walk(root):
        for f in sorted(files):
            if f.endswith(".rs"):
                found += functions(os.path.join(d, f))
    found.sort(reverse=True)
    for length, place, name in found[:n]:
        print(f"{length:5d}  {name}  {place}")
    print(f"{len(found)} functions, {sum(1 for f in found if f[0] > 80)} over 80 lines")


if __name__ == "__main__":
    main()
