#!/usr/bin/env python3
"""Point every citation of the methods reference at the repository's own document.

The code cites sections of the methods reference as `METHODS §x.y` (help texts, errors,
rustdoc, Python docstrings, tests, the README). This script rewrites each such citation to
`docs/methods.md §x.y`, the document in this repository that holds those sections, and keeps
comment lines within the line limit by rewrapping the comment paragraph it touched.

Usage (from anywhere; the repository is the parent of this script's folder):

    python3 tools/methods_refs.py            # rewrite, then `cargo fmt --all`
    python3 tools/methods_refs.py --check    # list what would change, exit 1 if anything
    python3 tools/methods_refs.py --no-fmt   # rewrite without running rustfmt

It is idempotent: a second run changes nothing. Re-run it after merging a branch that still
writes `METHODS §`. Lines it cannot bring under the limit (a long string literal, a line in a
code block) are listed for a hand fix. The tests in `crates/gmwm/tests/methods_reference.rs`
(`cargo test --release -p gmwm --test integration methods_reference`) fail while any old
citation is left or a cited section has no heading in docs/methods.md.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NEW = "docs/methods.md"
MAX_LINE = 100

# Where citations live; docs/ (the reference itself) and this script are left alone.
SCAN_DIRS = ["crates", "bench", ".ci"]
SCAN_FILES = ["README.md"]
EXTENSIONS = {".rs", ".py", ".pyi", ".md", ".toml", ".txt", ".sh", ".cfg", ".ini"}
SKIP_PARTS = {"target", ".git", "__pycache__", "node_modules", ".venv", "py-venv"}

# `METHODS` followed by a section sign, possibly on the next comment line:
# "(METHODS §1.7)", "METHODS\n/// §4.2", "METHODS\n# §7".
COMMENT_BREAK = r"[ \t]*(?:\n[ \t]*(?://[/!]?|#|\*)?[ \t]*)?"
# In Markdown the citation becomes a link to the section's heading.
MD_CITATION = re.compile(r"\bMETHODS[ \t]*\n?[ \t]*§(\d+(?:\.\d+)?)")
HEADING = re.compile(r"^#{1,6}[ \t]+(§(\d+(?:\.\d+)?)[ \t].*?)[ \t]*$", re.M)
CITATION = re.compile(r"\bMETHODS(?=" + COMMENT_BREAK + "§)")

RUST_COMMENT = re.compile(r"^(?P<lead>[ \t]*)(?P<mark>//[/!]?)(?P<gap> ?)(?P<text>.*)$")
HASH_COMMENT = re.compile(r"^(?P<lead>[ \t]*)(?P<mark>#)(?P<gap> ?)(?P<text>.*)$")
SYNTAX = {"rust": True}  # comment syntax of the file being rewritten
BLOCK_START = re.compile(r"^([-+*>|=#]|\d+[.)]$|```)")
LIST_ITEM = re.compile(r"^(?P<indent> *)(?P<bullet>[-*+] |\d+\. )")


def files_to_scan(root: Path):
    out = []
    for name in SCAN_FILES:
        p = root / name
        if p.is_file():
            out.append(p)
    for d in SCAN_DIRS:
        base = root / d
        if not base.is_dir():
            continue
        for p in sorted(base.rglob("*")):
            if not p.is_file() or SKIP_PARTS.intersection(p.relative_to(root).parts):
                continue
            if p.suffix in EXTENSIONS or p.parent.name == ".ci":
                out.append(p)
    return out


def github_slug(title: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces to hyphens."""
    kept = "".join(ch for ch in title.lower() if ch.isalnum() or ch in " -_")
    return kept.replace(" ", "-")


def section_anchors(root: Path):
    """Section number -> anchor in docs/methods.md, from its headings."""
    doc = root / NEW
    if not doc.is_file():
        return {}
    text = doc.read_text(encoding="utf-8")
    return {m.group(2): github_slug(m.group(1)) for m in HEADING.finditer(text)}


def markdown_link(path: Path, root: Path, anchors):
    rel = Path(*([".."] * (len(path.relative_to(root).parts) - 1)), NEW).as_posix()

    def sub(m):
        number = m.group(1)
        anchor = anchors.get(number)
        target = f"{rel}#{anchor}" if anchor else rel
        return f"[{NEW} §{number}]({target})"

    return sub


def comment_parts(line: str):
    """(prefix, text) of a `//`, `///`, `//!` or `#` comment line, else None."""
    m = (RUST_COMMENT if SYNTAX["rust"] else HASH_COMMENT).match(line)
    if not m:
        return None
    prefix = m.group("lead") + m.group("mark") + m.group("gap")
    return prefix, m.group("text")


def continuation_indent(text: str) -> str:
    """Indentation that the next line of this comment paragraph carries."""
    m = LIST_ITEM.match(text)
    if m:
        return " " * (len(m.group("indent")) + len(m.group("bullet")))
    return text[: len(text) - len(text.lstrip(" "))]


def is_plain_continuation(text: str, indent: str) -> bool:
    """Whether a comment line's text continues the paragraph above at `indent`."""
    if not text.strip() or not text.startswith(indent):
        return False
    rest = text[len(indent):]
    if rest.startswith(" ") or LIST_ITEM.match(rest):
        return False
    return not rest.startswith(("|", "```", "#", ">", "<", "    "))


def fenced_lines(lines):
    """Indices of comment lines inside a ``` code fence (never rewrapped)."""
    inside, fenced = False, set()
    for i, line in enumerate(lines):
        parts = comment_parts(line)
        if parts and parts[1].lstrip().startswith("```"):
            inside = not inside
            fenced.add(i)
        elif inside:
            fenced.add(i)
    return fenced


def rewrap(lines, i, fenced, limit=MAX_LINE):
    """Bring comment line i under the limit by moving its last words to the next line of the
    paragraph (or a new line), cascading; returns False if the line is not a rewrappable
    comment."""
    guard = 0
    while len(lines[i].rstrip("\n")) > limit:
        guard += 1
        if guard > 1000 or i in fenced:
            return False
        parts = comment_parts(lines[i].rstrip("\n"))
        if parts is None:
            return False
        prefix, text = parts
        if text.lstrip().startswith("|"):
            return False  # a table row cannot be wrapped
        indent = continuation_indent(text)
        lead = len(text) - len(text.lstrip(" "))
        words = text[lead:].split(" ")
        keep = len(words)
        while keep > 1 and len(prefix) + lead + len(" ".join(words[:keep])) > limit:
            keep -= 1
        # a moved word must not open a Markdown block on its new line (a list, a heading...)
        while keep > 1 and BLOCK_START.match(words[keep]):
            keep -= 1
        if keep == len(words) or keep < 1:
            return False
        head, tail = words[:keep], words[keep:]
        while head and head[-1] == "":
            head.pop()
        tail = [w for w in tail if w != ""]
        lines[i] = prefix + text[:lead] + " ".join(head) + "\n"
        nxt = i + 1
        nparts = comment_parts(lines[nxt].rstrip("\n")) if nxt < len(lines) else None
        if (
            nparts is not None
            and nparts[0] == prefix
            and nxt not in fenced
            and is_plain_continuation(nparts[1], indent)
        ):
            rest = nparts[1][len(indent):]
            lines[nxt] = prefix + indent + " ".join(tail + [rest]) + "\n"
        else:
            # shift the fence indices below the inserted line
            shifted = {k + 1 if k >= nxt else k for k in fenced}
            fenced.clear()
            fenced.update(shifted)
            lines.insert(nxt, prefix + indent + " ".join(tail) + "\n")
        i = nxt
    return True


def rewrite_file(path: Path, root: Path, anchors):
    """Rewritten text of one file and the lines left over the limit (1-based), or None."""
    old = path.read_text(encoding="utf-8")
    SYNTAX["rust"] = path.suffix == ".rs"
    if "METHODS" not in old:
        return None
    if path.suffix == ".md":
        new = MD_CITATION.sub(markdown_link(path, root, anchors), old)
        return (new, []) if new != old else None
    new = CITATION.sub(NEW, old)
    if new == old:
        return None
    old_lines = old.splitlines(keepends=True)
    lines = new.splitlines(keepends=True)
    touched = [
        i for i, line in enumerate(lines)
        if NEW in line and (i >= len(old_lines) or line != old_lines[i])
    ]
    fenced = fenced_lines([ln.rstrip("\n") for ln in lines])
    offset, overlong = 0, []
    for i in touched:
        j = i + offset
        before = len(lines)
        was = len(old_lines[i].rstrip("\n")) if i < len(old_lines) else 0
        if len(lines[j].rstrip("\n")) <= max(MAX_LINE, was):
            continue
        ok = rewrap(lines, j, fenced)
        offset += len(lines) - before
        if not ok:
            overlong.append(j + 1)
    return "".join(lines), overlong


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="list files that would change")
    ap.add_argument("--no-fmt", action="store_true", help="do not run `cargo fmt --all`")
    ap.add_argument("--root", type=Path, default=ROOT, help="repository root")
    args = ap.parse_args()
    root = args.root.resolve()
    changed, overlong = [], []
    anchors = section_anchors(root)
    for path in files_to_scan(root):
        result = rewrite_file(path, root, anchors)
        if result is None:
            continue
        text, long_lines = result
        rel = path.relative_to(root)
        changed.append(rel)
        overlong += [f"{rel}:{n}" for n in long_lines]
        if not args.check:
            path.write_text(text, encoding="utf-8")
    verb = "would rewrite" if args.check else "rewrote"
    for rel in changed:
        print(f"{verb} {rel}")
    print(f"{len(changed)} files {'to rewrite' if args.check else 'rewritten'}", file=sys.stderr)
    if changed and not args.check and not args.no_fmt:
        rs = any(str(p).endswith(".rs") for p in changed)
        if rs:
            subprocess.run(["cargo", "fmt", "--all"], cwd=root, check=False)
    for loc in overlong:
        print(f"{loc}: longer than {MAX_LINE} characters after the rewrite; fix by hand",
              file=sys.stderr)
    if args.check:
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
