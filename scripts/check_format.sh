#!/usr/bin/env bash
# Checks that every C++ source is formatted by .clang-format (Debian 12's clang-format 14), and the
# house rules (scripts/check_house.py: no function over about 80 lines; a file past 800 is a prompt).
# With --fix, formats the files in place instead.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.h' '*.cpp' | grep -v '^extract/mc_tables.h$')
if [ "${1:-}" = "--fix" ]; then
    clang-format -i "${files[@]}"
    exit 0
fi
clang-format --dry-run --Werror "${files[@]}"
echo "format: ${#files[@]} files as .clang-format says"
/usr/bin/python3 scripts/check_house.py
