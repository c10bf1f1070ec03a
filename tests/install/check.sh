#!/usr/bin/env bash
# Installs the build into a fresh prefix and builds a consumer twice: with find_package(steadystep) and with
# pkg-config. Then compares what the installed library exports with what its installed headers declare: the same
# function names, and none of the lab's (scenes, runs, profiles). ODE_PC_DIR: the directory of the ode.pc the build
# used; the pkg-config consumer looks there first (the installed CMake package knows it).
# Usage: check.sh BUILD_DIR WORK_DIR [ODE_PC_DIR]
set -euo pipefail
build=$1 work=$2 ode_pc_dir=${3:-} here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$here" -B "$work/cmake" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/cmake" >/dev/null
"$work/cmake/consumer"
pc_path=$(dirname "$(find "$work/prefix" -name steadystep.pc)")
pc_path=$pc_path:$ode_pc_dir:${PKG_CONFIG_PATH:-}
cc "$here/consumer.c" -o "$work/consumer-pc" $(PKG_CONFIG_PATH=$pc_path pkg-config --cflags --libs steadystep) \
  -Wl,-rpath,"$(PKG_CONFIG_PATH=$pc_path pkg-config --variable=libdir steadystep)"
"$work/consumer-pc"
# Both consumers load one ODE: the one the library was built against, not the system's beside it.
for consumer in "$work/cmake/consumer" "$work/consumer-pc"; do
  odes=$(ldd "$consumer" | grep -c 'libode\.so' || true)
  [ "$odes" = 1 ] || { echo "$consumer loads $odes ODE libraries:"; ldd "$consumer" | grep libode; exit 1; }
done

library=$(find "$work/prefix" -name 'libsteadystep.so' | head -n 1)
if [ -z "$library" ]; then
  # A static core (SS_STATIC) marks nothing for export: linked into a game's shared object, it stays hidden there.
  archive=$(find "$work/prefix" -name 'libsteadystep.a' | head -n 1)
  visible=$(readelf -s --wide "$archive" | awk '$5 == "GLOBAL" && $6 == "DEFAULT" && $7 != "UND"' | wc -l)
  [ "$visible" = 0 ] || { echo "the static library has $visible symbols of default visibility"; exit 1; }
  echo "a static library: every symbol hidden"
  exit 0
fi
# The functions the installed headers declare: the names before "(" in the headers without comments, function
# types (typedef) left out.
for header in "$work"/prefix/include/steadystep/*.h; do
  cc -fpreprocessed -dD -E -P "$header" 2>/dev/null
done | grep -v '^\s*#' | tr '\n' ' ' | tr ';' '\n' | grep -v '^\s*typedef' \
  | grep -oE '\bss[A-Za-z0-9_]*\s*\(' | tr -d ' (' | sort -u > "$work/declared.txt"
nm -D --defined-only "$library" | awk '{print $3}' | sort -u > "$work/exported.txt"
if ! diff -u "$work/declared.txt" "$work/exported.txt" > "$work/difference.txt"; then
  echo "declared (-) and exported (+) differ:"
  grep '^[-+]ss' "$work/difference.txt"
  exit 1
fi
if grep -E 'Scene|Run_|Profile|Lab|Boxes|Rng' "$work/exported.txt"; then
  echo "the core exports the lab's functions above"
  exit 1
fi
if ls "$work"/prefix/include/steadystep | grep -E 'scene|profile|lab'; then
  echo "the lab's headers are installed"
  exit 1
fi
echo "exports $(wc -l < "$work/exported.txt") functions, all declared"
