#!/usr/bin/env bash
# Build the vendored ROS 2 interfaces (interfaces/*: vision_msgs, tf2_msgs, foxglove_msgs) into a pip-only venv.
#
#   scripts/build_interfaces.sh VENV_DIR [PACKAGE ...]      (default: every package under interfaces/)
#
# None of them is on PyPI, so on a machine without the ROS apt repository each is generated and compiled here
# from the .msg files in this repository, with the PyPI wheels of ROS 2 Jazzy (interfaces/requirements-build.txt),
# and installed into the venv prefix: VENV/share/PKG, VENV/lib/python3.11/site-packages/PKG, VENV/lib/lib*.so.
# Nothing else is needed at run time (the wheels' bootstrapper puts VENV/lib on the library path).
#
# A package is skipped when `from PKG.msg import <its first message>` with its type support already works in that
# venv and either no build of ours is recorded (a real ROS install provides it) or the recorded sha256 of its
# sources is unchanged. A changed .msg, package.xml, CMakeLists.txt, requirements-build.txt, or pin of a ros-*
# wheel or numpy in constraints.txt triggers a rebuild; the files of the previous build are removed first.
set -euo pipefail

die() { echo "build_interfaces: $1" >&2; exit "${2:-1}"; }

[ "$#" -ge 1 ] || die "usage: scripts/build_interfaces.sh VENV_DIR [PACKAGE ...]" 2
[ -x "$1/bin/python" ] || die "'$1' is not a virtual environment (no $1/bin/python)" 2
venv="$(cd "$1" && pwd)"
shift
py="$venv/bin/python"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
reqs="$root/interfaces/requirements-build.txt"
if [ "$#" -eq 0 ]; then
  set -- $(cd "$root/interfaces" && for d in */package.xml; do dirname "$d"; done)
fi

# Where the wheels were built; their exported CMake files hard-code these include paths.
wheel_py_prefix="/opt/python/cp311-cp311"

works() {  # works PKG MSG: importing the generated Python module is not enough, also load its C type support
  "$py" -c "from $1.msg import $2 as M
M.__class__.__import_type_support__()" >/dev/null 2>&1
}

sources_sha() {  # sources_sha SRC_DIR
  ( cd "$1"
    { find . -type f \( -name '*.msg' -o -name package.xml -o -name CMakeLists.txt \) -print0 \
        | LC_ALL=C sort -z | xargs -0 sha256sum
      sha256sum < "$reqs"
      # The ROS wheels and NumPy it is compiled against (not the rest of constraints.txt).
      { grep -iE '^(ros-|numpy==)' "$root/constraints.txt" || true; } | LC_ALL=C sort
    } | sha256sum | cut -d' ' -f1 )
}

prepared=""
prepare() {  # once: the build-only wheels, and their exported CMake include paths pointed at this venv
  [ -z "$prepared" ] || return 0
  prepared=1
  "$py" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' \
    || die "the ROS 2 Jazzy wheels on PyPI are for Python 3.11 only; $py is $("$py" -V 2>&1)"
  echo "[interfaces] installing build-only wheels (interfaces/requirements-build.txt)"
  "$py" -m pip install -q --disable-pip-version-check -r "$reqs" -c "$root/constraints.txt"
  # Idempotent (nothing left to replace after the first run) and limited to files inside the venv.
  pyinc="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
  npinc="$("$py" -c 'import numpy; print(numpy.get_include())')"
  [ -f "$pyinc/Python.h" ] \
    || die "Python headers not found ($pyinc/Python.h); install the Python 3.11 development headers"
  [ -d "$npinc/numpy" ] || die "NumPy headers not found in $npinc"
  mapfile -t to_patch < <(find_unpatched)
  if [ "${#to_patch[@]}" -gt 0 ]; then
    echo "[interfaces] patching ${#to_patch[@]} exported CMake files ($wheel_py_prefix -> this venv)"
    sed -i \
      -e "s|$wheel_py_prefix/lib/python3.11/site-packages/numpy/_core/include|$npinc|g" \
      -e "s|$wheel_py_prefix/include/python3.11|$pyinc|g" \
      "${to_patch[@]}"
    left="$(find_unpatched)"
    [ -z "$left" ] || die "unexpected $wheel_py_prefix paths left in: $left"
  fi
}
find_unpatched() {
  grep -rlF --include='*.cmake' "$wheel_py_prefix" "$venv/share" "$venv/lib" 2>/dev/null || true
}

build_one() {  # build_one PKG
  local pkg="$1" src="$root/interfaces/$1"
  [ -f "$src/package.xml" ] || die "interface sources not found: $src/package.xml"
  local probe
  probe="$(cd "$src/msg" && ls -1 *.msg | LC_ALL=C sort | head -n 1)"
  probe="${probe%.msg}"
  local stamp="$venv/share/$pkg/.iemd_sources.sha256"
  local manifest="$venv/share/$pkg/.iemd_install_manifest.txt"
  local want
  want="$(sources_sha "$src")"
  if [ -f "$stamp" ]; then
    if [ "$(cat "$stamp")" = "$want" ] && works "$pkg" "$probe"; then
      echo "[$pkg] up to date in $venv"
      return 0
    fi
    echo "[$pkg] interface sources changed (or previous build broken): rebuilding"
  elif works "$pkg" "$probe"; then
    echo "[$pkg] already provided by $("$py" -c "import os, $pkg; print(os.path.dirname($pkg.__file__))"): nothing to build"
    return 0
  fi
  prepare
  local start=$SECONDS build log
  build="$(mktemp -d "${TMPDIR:-/tmp}/${pkg}_build.XXXXXX")"
  log="$build/build.log"
  # A hermetic build: only this venv's packages, whatever ROS environment the shell has sourced.
  cm() {
    env -u AMENT_PREFIX_PATH -u CMAKE_PREFIX_PATH -u PYTHONPATH "$venv/bin/cmake" "$@" >>"$log" 2>&1
  }
  fail() {
    tail -n 40 "$log" >&2 || true
    die "$pkg: $1 failed (full log: $log)"
  }
  echo "[$pkg] configuring and building in $build"
  cm -S "$src" -B "$build" -G "Unix Makefiles" \
    -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$venv" \
    -DCMAKE_PREFIX_PATH="$venv" \
    -DPython3_EXECUTABLE="$py" \
    -DPython3_FIND_VIRTUALENV=ONLY \
    -DBUILD_TESTING=OFF || fail "cmake configure"
  cm --build "$build" --parallel "$(nproc)" || fail "cmake build"
  if [ -f "$manifest" ]; then
    # Remove the files of our previous build (a message may have been renamed or removed).
    while IFS= read -r f; do
      case "$f" in "$venv"/*) rm -f -- "$f" ;; esac
    done < "$manifest"
  fi
  cm --install "$build" || fail "cmake install"
  cp "$build/install_manifest.txt" "$manifest"
  works "$pkg" "$probe" || die "installed, but $pkg.msg.$probe or its type support fails in $venv"
  echo "$want" > "$stamp"
  rm -rf "$build"
  echo "[$pkg] installed into $venv in $((SECONDS - start)) s"
}

for pkg in "$@"; do
  build_one "$pkg"
done
