#!/usr/bin/env bash
# Count the public declarations of the gmwm engine, reproducibly, from the source text.
#
# Method: every line of crates/gmwm/src/**/*.rs is scanned, after removing
# `#[cfg(test)] mod tests { ... }` blocks at the end of files (everything from the line
# `#[cfg(test)]` that precedes `mod tests` to the end of the file), for
#   items:  `pub` (exactly `pub`, not `pub(crate)`/`pub(super)`/`pub(in ..)`) followed by
#           fn | struct | enum | trait | type | const | static | mod | use, allowing the
#           qualifiers `async`, `unsafe`, `const`, `extern "C"` before `fn`;
#           methods in `impl` blocks count as `pub fn` (trait impls have no `pub`);
#   fields: lines `pub NAME:` (named struct fields and tuple-less field declarations).
# A `pub use a::{b, c}` counts as one item. An item is counted whether or not the module that
# holds it is reachable from the crate root; the number is a size of the declared surface,
# the ordering of which is what matters between two runs.
#
# Usage: crates/gmwm/tools/count_pub.sh [--by-kind] [--by-file]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)/src"
strip_tests() {
    awk '
        /^#\[cfg\(test\)\]/ { pending = 1; next }
        pending && /^mod tests/ { skip = 1 }
        pending && !skip { print prev_cfg; }
        { pending = 0 }
        !skip { print }
    ' prev_cfg='#[cfg(test)]' "$1"
}
item_re='^[[:space:]]*pub[[:space:]]+((async|unsafe|const|extern[[:space:]]+"C")[[:space:]]+)*(fn|struct|enum|trait|type|const|static|mod|use)[[:space:]]'
field_re='^[[:space:]]*pub[[:space:]]+[a-z_][a-z0-9_]*[[:space:]]*:'
items=0 fields=0
declare -A kind
by_file=""
while IFS= read -r f; do
    text="$(strip_tests "$f")"
    i=$(grep -cE "$item_re" <<<"$text" || true)
    d=$(grep -cE "$field_re" <<<"$text" || true)
    items=$((items + i)) fields=$((fields + d))
    by_file+="$(printf '%5d %5d  %s' "$i" "$d" "${f#"$root"/}")"$'\n'
    while read -r k; do
        [ -n "$k" ] && kind[$k]=$(( ${kind[$k]:-0} + 1 ))
    done < <(grep -E "$item_re" <<<"$text" | sed -E 's/^[[:space:]]*pub[[:space:]]+((async|unsafe|const|extern[[:space:]]+"C")[[:space:]]+)*([a-z]+).*/\3/' || true)
done < <(find "$root" -name '*.rs' | sort)
echo "pub items:  $items"
echo "pub fields: $fields"
if [[ " $* " == *" --by-kind "* ]]; then
    for k in "${!kind[@]}"; do printf '  %-7s %d\n' "$k" "${kind[$k]}"; done | sort
fi
if [[ " $* " == *" --by-file "* ]]; then
    echo "items fields file"
    printf '%s' "$by_file"
fi
