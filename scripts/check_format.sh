#!/usr/bin/env bash
# Checks that every C++ source is formatted by .clang-format (Debian 12's clang-format 14), and the
# house rules (scripts/check_house.py: no file over 400 lines, no function over about 80).
# With --fix, formats the files in place instead.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.h' '*.cpp' | grep -v '^common/extract/mc_tables.h$')
if [ "${1:-}" = "--fix" ]; then
    clang-format -i "${files[@]}"
    exit 0
fi
clang-format --dry-run --Werror "${files[@]}"
echo "format: ${#files[@]} files as .clang-format says"
/usr/bin/python3 scripts/check_house.py
