#!/usr/bin/env bash
# Builds ODE in single precision from Debian's own source package, once, and prints its install prefix.
#
# Debian's libode-dev is double precision; ODE's own build defaults to single, and many programs ship an ODE they
# built so. scripts/test runs every C test against both. The source is the Debian source package of the ODE the
# machine has installed (libode-dev, 2:0.16.2-1 on bookworm), fetched with `apt-get source` through a private
# deb-src list made from the machine's own Debian deb entries (/etc/apt/sources.list*), with its own lists and
# cache under build/: the machine's apt configuration and state are not touched. Nothing is vendored, nothing comes
# from anywhere else. It is built with ODE's CMake build (Release, -DODE_DOUBLE_PRECISION=OFF, no demos, no tests)
# into build/ode-single/prefix, which is reused as long as its stamp names the same source version and options.
#
# --asserts builds it instead as Debug compiled at -O2, into build/ode-single-asserts/prefix: ODE's CMake defines
# dNODEBUG in every configuration but Debug, which compiles its asserts out, so only this build aborts where Debian's
# double build would. The tests use the Release build: with the asserts, ODE's float dWorldStep aborts on a joint far
# from holding (docs/precision.md), a state the stepper cannot see, and the fuzzers reach it within seconds.
#
# Usage: scripts/ode-single.sh [--asserts]   (prints the prefix; build with -DSTEADYSTEP_ODE_PREFIX=<prefix>)
# Needs: apt-get, dpkg-source (dpkg-dev), cmake, ninja, g++, and the network to reach the Debian mirror.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_type=(-DCMAKE_BUILD_TYPE=Release)
root="$repo/build/ode-single"
case "${1:-}" in
  "") ;;
  --asserts)
    build_type=(-DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_FLAGS_DEBUG=-O2 -DCMAKE_CXX_FLAGS_DEBUG=-O2)
    root="$repo/build/ode-single-asserts"
    ;;
  *) echo "usage: scripts/ode-single.sh [--asserts]" >&2; exit 2 ;;
esac
prefix="$root/prefix"

# The source version: that of the installed double-precision libode-dev, so that both builds are the same ODE.
version=$(dpkg-query -W -f='${Version}' libode-dev 2>/dev/null || true)
case "$version" in
  *:0.16.2-*) ;;
  *) echo "ode-single: needs Debian's libode-dev 0.16.2 installed (found '${version:-none}')" >&2; exit 1 ;;
esac
options=("${build_type[@]}" -DODE_DOUBLE_PRECISION=OFF -DODE_WITH_DEMOS=OFF -DODE_WITH_TESTS=OFF
         -DBUILD_SHARED_LIBS=ON -DCMAKE_INSTALL_LIBDIR=lib)
stamp="ode $version ${options[*]}"
if [ -f "$prefix/stamp" ] && [ "$(cat "$prefix/stamp")" = "$stamp" ] && [ -f "$prefix/lib/pkgconfig/ode.pc" ]; then
  echo "$prefix"
  exit 0
fi

# A private apt: a deb-src line for each of the machine's Debian deb entries (same URI, suites, components and
# signing key), its own lists and cache, no other source parts.
apt="$root/apt"
rm -rf "$apt" "$root/src" "$root/build" "$prefix"
mkdir -p "$apt/lists/partial" "$apt/cache/archives/partial" "$apt/parts" "$root/src"
list="$apt/sources.list"
{
  # deb822 .sources stanzas (Types/URIs/Suites/Components/Signed-By)
  for file in /etc/apt/sources.list.d/*.sources; do
    [ -f "$file" ] || continue
    awk '
      function flush() {
        if (types ~ /(^| )deb( |$)/ && uris ~ /debian/)
          { n = split(uris, u, " "); m = split(suites, s, " ");
            for (i = 1; i <= n; ++i) for (j = 1; j <= m; ++j)
              printf "deb-src%s %s %s %s\n", (key != "" ? " [signed-by=" key "]" : ""), u[i], s[j], comps }
        types = uris = suites = comps = key = "" }
      /^[ \t]*#/ { next }
      /^[ \t]*$/ { flush(); next }
      { field = $1; sub(/:$/, "", field); $1 = ""; sub(/^ +/, "");
        if (field == "Types") types = $0; else if (field == "URIs") uris = $0;
        else if (field == "Suites") suites = $0; else if (field == "Components") comps = $0;
        else if (field == "Signed-By") key = $0 }
      END { flush() }' "$file"
  done
  # one-line lists: deb [options] uri suite components...
  for file in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$file" ] || continue
    awk '$1 == "deb" && /debian/ { $1 = "deb-src"; print }' "$file"
  done
} | sort -u >"$list"
if [ ! -s "$list" ]; then
  echo "ode-single: no Debian deb entry in /etc/apt/sources.list* to make a deb-src line from" >&2
  exit 1
fi
aptopts=(-o "Dir::Etc::SourceList=$list" -o "Dir::Etc::SourceParts=$apt/parts" -o "Dir::State::Lists=$apt/lists"
         -o "Dir::Cache=$apt/cache" -o "APT::Sandbox::User=root")
echo "ode-single: fetching Debian's source package ode=$version ($(wc -l <"$list") deb-src lines in $list)" >&2
apt-get -qq "${aptopts[@]}" update >&2
(cd "$root/src" && apt-get -qq "${aptopts[@]}" source --only-source "ode=$version" >&2)
source_dir=$(find "$root/src" -mindepth 1 -maxdepth 1 -type d -name 'ode-*' | head -n 1)
[ -f "$source_dir/CMakeLists.txt" ] || { echo "ode-single: no ODE source tree under $root/src" >&2; exit 1; }

echo "ode-single: building ODE in single precision into $prefix" >&2
start=$SECONDS
cmake -S "$source_dir" -B "$root/build" -G Ninja "${options[@]}" -DCMAKE_INSTALL_PREFIX="$prefix" >&2
cmake --build "$root/build" -j "$(nproc)" >&2
cmake --install "$root/build" >&2
precision=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --variable=precision ode)
[ "$precision" = dSINGLE ] || { echo "ode-single: the build says precision=$precision, not dSINGLE" >&2; exit 1; }
rm -rf "$apt" "$root/build"  # the source stays in $root/src, to read
echo "$stamp" >"$prefix/stamp"
echo "ode-single: built in $((SECONDS - start)) s" >&2
echo "$prefix"
