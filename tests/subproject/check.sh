#!/usr/bin/env bash
# Configures and builds tests/subproject (a parent project that adds steadystep with add_subdirectory), runs its
# program, and checks that the build has no test, bench, example or lab target and no ctest test.
# Usage: check.sh STEADYSTEP_SOURCE_DIR WORK_DIR
set -euo pipefail
source=$1 work=$2 here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work/.cmake/api/v1/query"
# CMake's file API lists every target of the build, the parent's and steadystep's: one reply file per target,
# target-NAME-Release-HASH.json.
touch "$work/.cmake/api/v1/query/codemodel-v2"
cmake -S "$here" -B "$work" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSTEADYSTEP_DIR="$source" >/dev/null
cmake --build "$work" >/dev/null
"$work/parent_program"
ls "$work/.cmake/api/v1/reply" | sed -n 's/^target-\(.*\)-Release-[0-9a-f]*\.json$/\1/p' | sort > "$work/targets.txt"
grep -qx 'parent_program' "$work/targets.txt"
grep -qx 'steadystep' "$work/targets.txt"
if grep -E 'test|bench|example|lab|gtest|ode_probe' "$work/targets.txt"; then
  echo "the parent got the targets above"
  exit 1
fi
tests=$(ctest --test-dir "$work" -N | sed -n 's/^Total Tests: //p')
echo "no test, bench or example targets, ${tests} tests"
