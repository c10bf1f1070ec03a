#!/usr/bin/env bash
# Installs the build into a fresh prefix and builds a consumer twice: with find_package(steadystep) and with
# pkg-config. Usage: check.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1 work=$2 here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$here" -B "$work/cmake" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/cmake" >/dev/null
"$work/cmake/consumer"
pc_path=$(dirname "$(find "$work/prefix" -name steadystep.pc)")
cc "$here/consumer.c" -o "$work/consumer-pc" $(PKG_CONFIG_PATH=$pc_path pkg-config --cflags --libs steadystep) \
  -Wl,-rpath,"$(PKG_CONFIG_PATH=$pc_path pkg-config --variable=libdir steadystep)"
"$work/consumer-pc"
