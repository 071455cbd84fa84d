#!/usr/bin/env bash
# The ctest test `readme_example`: README.md shows tests/packaging/plan_one_board.cpp, the program
# the `packaging` test builds against an installed hila, as one ```cpp block, verbatim.
#
# Usage: readme_example.sh README.md plan_one_board.cpp
set -euo pipefail

readme="$1"
example="$2"
blocks="$(mktemp -d)"
trap 'rm -rf "$blocks"' EXIT

# Every ```cpp block of the README into its own file, fences left out.
awk -v dir="$blocks" '
  /^```cpp[[:space:]]*$/ { inside = 1; n++; file = dir "/" n ".cpp"; printf "" > file; next }
  inside && /^```[[:space:]]*$/ { inside = 0; close(file); next }
  inside { print >> file }
' "$readme"

for block in "$blocks"/*.cpp; do
  [ -e "$block" ] || break
  if cmp -s "$block" "$example"; then
    echo "readme_example: $readme shows $example verbatim"
    exit 0
  fi
done

echo "FAIL: $readme has no \`\`\`cpp block equal to $example." >&2
echo "Paste the file's whole text between a \`\`\`cpp line and a \`\`\` line (the packaging" >&2
echo "test builds and runs that file against an installed hila, so the README's example works)." >&2
exit 1
