#!/usr/bin/env python3
"""Narrow the engine's public surface to what its users name.

The users of `crates/gmwm` are the CLI, the figures/report crate, the Python package, the fuzz
targets, the engine's benches and examples, its public-API test and its doc examples. Every
identifier they spell is collected; a `pub` item or field of the engine (outside `src/tests/`)
whose name none of them spells becomes `pub(crate)`. Names are matched as tokens, so a common
method name (`new`, `wv`) keeps every item of that name public: the rule only ever narrows
what no user can be naming.

Usage: python3 tools/demote_unused_pub.py [--dry-run]
"""
import pathlib
import re
import sys

root = pathlib.Path(__file__).resolve().parent.parent
users = [
    root / "crates/gmwm-cli",
    root / "crates/gmwm-plot",
    root / "crates/gmwm-py",
    root / "fuzz/fuzz_targets",
    root / "fuzz/src",
    root / "crates/gmwm/benches",
    root / "crates/gmwm/examples",
    root / "crates/gmwm/tests",
]
ident = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
tokens = set()
for d in users:
    for f in d.rglob("*.rs"):
        if "target" in f.parts:
            continue
        tokens.update(ident.findall(f.read_text()))

# Types a public signature shows (found by `private_interfaces`): public with it.
keep = root / "tools/public_api_keep.txt"
if keep.exists():
    tokens.update(keep.read_text().split())

engine = root / "crates/gmwm/src"
doc_block = re.compile(r"^\s*//[/!] ?```")
for f in engine.rglob("*.rs"):
    in_code = False
    for line in f.read_text().splitlines():
        if doc_block.match(line):
            in_code = not in_code
            continue
        if in_code and re.match(r"^\s*//[/!]", line):
            tokens.update(ident.findall(line))

item = re.compile(
    r"^(\s*)pub(\s+(?:(?:async|unsafe|const)\s+)*(?:fn|struct|enum|trait|type|const|static)\s+)(r#)?([A-Za-z_][A-Za-z0-9_]*)"
)
field = re.compile(r"^(\s*)pub(\s+)([a-z_][a-z0-9_]*)(\s*:)")
dry = "--dry-run" in sys.argv
changed = 0
for f in sorted(engine.rglob("*.rs")):
    if "tests" in f.relative_to(engine).parts:
        continue
    lines = f.read_text().split("\n")
    out = []
    for line in lines:
        m = item.match(line)
        if m and m.group(4) not in tokens:
            line = f"{m.group(1)}pub(crate){line[len(m.group(1)) + 3:]}"
            changed += 1
        else:
            m = field.match(line)
            if m and m.group(3) not in tokens:
                line = f"{m.group(1)}pub(crate){line[len(m.group(1)) + 3:]}"
                changed += 1
        out.append(line)
    if not dry:
        f.write_text("\n".join(out))
print(f"{changed} declarations narrowed to pub(crate)")

# Re-exports: `pub use path::{A, B}` keeps public the names a user spells and re-exports the
# others `pub(crate)` (a re-export cannot be wider than its item).
use_stmt = re.compile(r"^(\s*)pub use ([^;]*);", re.S | re.M)
renamed = 0
for f in sorted(engine.rglob("*.rs")):
    if "tests" in f.relative_to(engine).parts:
        continue
    text = f.read_text()

    def split(m):
        global renamed
        indent, body = m.group(1), m.group(2)
        body_flat = " ".join(body.split())
        if "{" not in body_flat:
            name = body_flat.split("::")[-1].split(" as ")[-1].strip()
            if name in tokens or name == "*" or name == "self":
                return m.group(0)
            renamed += 1
            return f"{indent}pub(crate) use {body_flat};"
        prefix, rest = body_flat.split("{", 1)
        names = [n.strip() for n in rest.rsplit("}", 1)[0].split(",") if n.strip()]
        if any("{" in n or "}" in n for n in names):
            return m.group(0)
        keep = [n for n in names if n.split(" as ")[-1].split("::")[-1] in tokens]
        drop = [n for n in names if n not in keep]
        if not drop:
            return m.group(0)
        renamed += len(drop)
        out = []
        if keep:
            out.append(f"{indent}pub use {prefix}{{{', '.join(keep)}}};")
        out.append(f"{indent}pub(crate) use {prefix}{{{', '.join(drop)}}};")
        return "\n".join(out)

    new = use_stmt.sub(split, text)
    if new != text and not dry:
        f.write_text(new)
print(f"{renamed} re-exports narrowed to pub(crate)")
