# Sourced by scripts/test and scripts/report: installs what the project needs on a fresh Debian machine.
# As root it installs missing Debian packages with apt-get; otherwise it prints one line naming them and the exact
# command, and exits 2 (tests/python/test_deps_script.py).
# Then it makes the Python virtual environment .venv under the repository and installs the package into it.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

missing=()
command -v cmake >/dev/null || missing+=(cmake)
command -v ninja >/dev/null || missing+=(ninja-build)
command -v g++ >/dev/null || missing+=(g++)
command -v pkg-config >/dev/null || missing+=(pkg-config)
pkg-config --exists ode 2>/dev/null || missing+=(libode-dev)
command -v dpkg-source >/dev/null || missing+=(dpkg-dev)  # scripts/ode-single.sh unpacks ODE's source package
[ -f /usr/include/gtest/gtest.h ] || missing+=(libgtest-dev)
python3 -c 'import ensurepip, venv' 2>/dev/null || missing+=(python3-venv)
# PyODE (`import ode`), the other Python binding of ODE, linked to the same libode.so.8: tests/python/test_pyode.py.
dpkg-query -W -f='${Status}' python3-pyode 2>/dev/null | grep -q 'ok installed' || missing+=(python3-pyode)
command -v chromium >/dev/null || [ "${0##*/}" = report ] || missing+=(chromium)  # tests/python/test_page.py
# Fuzzing (scripts/fuzz, run by the full scripts/test that CI runs): clang and its libFuzzer runtime.
if [ "${STEADYSTEP_NEED_FUZZ:-0}" = 1 ]; then
  command -v clang >/dev/null || missing+=(clang)
  compgen -G "/usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a" >/dev/null ||
    missing+=(libclang-rt-14-dev)
fi
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then
    echo "steadystep: installing Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq "${missing[@]}" >/dev/null
  else
    # One line, naming the packages and the command; exit 2, as every error that names its fix (issue 28).
    echo "steadystep: missing Debian packages ${missing[*]}: run 'sudo apt-get install -y ${missing[*]}' (as root)," \
         "then run me again" >&2
    exit 2
  fi
fi

# The Python package: built by scikit-build-core from the same CMake project.
venv="$repo/.venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --upgrade pip
fi
# The build needs cffi itself: it parses the headers into the binding (python/steadystep/core/_cdef_build.py).
"$venv/bin/pip" install --quiet scikit-build-core cffi
# test: pytest and ode-python (the tests' own ODE worlds); report: matplotlib and tqdm (figures, the report);
# dask: Dask distributed, so that the tests run studies on a real (local) cluster.
"$venv/bin/pip" install --quiet --no-build-isolation "$repo[test,report,dask]"

# The virtual environment sees Debian's PyODE, and only it: a directory holding a link to its extension module, put
# on the path by a .pth file. (--system-site-packages would show every Debian package, and nothing of Debian's when
# the venv's Python is another build of the same version, as pyenv's.) Done again on every run: idempotent.
if ! "$venv/bin/python" -c 'import ode' 2>/dev/null; then
  pyode=$(/usr/bin/python3 -c 'import ode; print(ode.__file__)')
  suffix=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
  if [ "${pyode%"$suffix"}" = "$pyode" ]; then
    echo "steadystep: Debian's PyODE ($pyode) is not built for the virtual environment's Python (its modules end in" \
         "$suffix): make .venv with Debian's python3 (rm -r $venv, then run me again)" >&2
    exit 1
  fi
  site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_path("platlib"))')
  mkdir -p "$venv/debian-pyode"
  ln -sfn "$pyode" "$venv/debian-pyode/${pyode##*/}"
  echo "$venv/debian-pyode" > "$site/steadystep-debian-pyode.pth"
  "$venv/bin/python" -c 'import ode' || { echo "steadystep: the virtual environment cannot import PyODE" >&2; exit 1; }
fi

