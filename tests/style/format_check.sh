#!/usr/bin/env bash
# The style.format test: every C++ file of the repository is as clang-format (the .clang-format
# at the root) leaves it. Debian 12's clang-format 14 is the reference; another major version
# formats some constructs differently, so there the test is skipped (exit 77), not failed.
# Fix a failure with: clang-format -i FILE...   Usage: tests/style/format_check.sh ROOT
set -euo pipefail
cd "$1"
v=$(clang-format --version 2>/dev/null | sed -n 's/.*version \([0-9]*\)\..*/\1/p')
if [ "$v" != 14 ]; then
  echo "style.format: clang-format 14 expected (Debian 12), found '${v:-none}': skipped"
  exit 77
fi
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.h' ':!:node_modules/*')
else
  mapfile -t files < <(find apps bench fuzz include python src tests -name '*.cpp' -o -name '*.h')
fi
bad=()
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [ "${#bad[@]}" -gt 0 ]; then
  echo "style.format: ${#bad[@]} of ${#files[@]} files differ from clang-format's output:"
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "style.format: ${#files[@]} files as clang-format leaves them"
