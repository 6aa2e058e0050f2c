#!/usr/bin/env python3
"""Mark `#[cfg(test)]` every item of the engine that only its tests use.

Reads `cargo build --message-format=json` output of the engine on stdin and, for each
`dead_code` warning, puts `#[cfg(test)]` on the line before each item it names (after its
doc comment and attributes). Run until no dead_code warning is left.
"""
import json
import sys
from collections import defaultdict

edits = defaultdict(set)
for line in sys.stdin:
    try:
        msg = json.loads(line)
    except json.JSONDecodeError:
        continue
    m = msg.get("message") if msg.get("reason") == "compiler-message" else None
    if not m or not m.get("code") or m["code"]["code"] != "dead_code":
        continue
    for s in (s for s in m["spans"] if s["is_primary"]):
        edits[s["file_name"]].add(s["line_start"])
for f, lines in edits.items():
    text = open(f).read().split("\n")
    for ln in sorted(lines, reverse=True):
        i = ln - 1
        item = text[i]
        indent = item[: len(item) - len(item.lstrip())]
        # walk up over attributes so cfg(test) sits right above the doc comment's end
        j = i
        while j > 0 and text[j - 1].strip().startswith("#[") and "cfg(test)" not in text[j - 1]:
            j -= 1
        if j > 0 and "cfg(test)" in text[j - 1]:
            continue
        text.insert(j, f"{indent}#[cfg(test)]")
    open(f, "w").write("\n".join(text))
    print(f, len(lines))
