#!/usr/bin/env bash
# Fails, naming the files, when a tracked C++ file is not as clang-format
# (with the tree's .clang-format) writes it. Fix with: clang-format -i FILE
# The files go to clang-format 40 at a time, two at once: one process per
# file took 36-60 s of a CI run, most of it starting clang-format.
set -euo pipefail
cd "$1"
command -v clang-format >/dev/null || { echo "clang-format is not installed (scripts/setup.sh --with-test-tools)" >&2; exit 1; }
mapfile -t files < <(git ls-files '*.cc' '*.h' 2>/dev/null || find . -path ./build -prune -o \( -name '*.cc' -o -name '*.h' \) -print)
# Each unformatted place is reported as "FILE:LINE:COL: error: code should be clang-formatted".
status=0
report=$(printf '%s\0' "${files[@]}" | xargs -0 -n 40 -P 2 clang-format --dry-run -Werror 2>&1 >/dev/null) || status=$?
mapfile -t bad < <(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: .*/\1/p' <<<"$report" | sort -u)
if ((${#bad[@]})); then
  printf 'not clang-formatted: %s\n' "${bad[@]}" >&2
  exit 1
fi
if ((status)); then  # clang-format failed otherwise (a file it cannot read or parse)
  printf 'clang-format failed (exit %d):\n%s\n' "$status" "$report" >&2
  exit 1
fi
echo "clang_format: ${#files[@]} files formatted"
