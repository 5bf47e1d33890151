#!/usr/bin/env bash
# Build the vendored vision_msgs interface (interfaces/vision_msgs) into a pip-only venv.
#
#   scripts/build_vision_msgs.sh VENV_DIR
#
# vision_msgs is not on PyPI, so on a machine without the ROS apt repository it is generated and
# compiled here from the .msg files in this repository, with the PyPI wheels of ROS 2 Jazzy
# (interfaces/requirements-build.txt), and installed into the venv prefix:
#   VENV/share/vision_msgs, VENV/lib/python3.11/site-packages/vision_msgs, VENV/lib/lib*.so
# Nothing else is needed at run time (the wheels' bootstrapper puts VENV/lib on the library path).
#
# Does nothing when `from vision_msgs.msg import ...` with its type support already works in that
# venv and either no build of ours is recorded (a real ROS install provides it) or the recorded
# sha256 of the interface sources is unchanged. A changed .msg, package.xml, CMakeLists.txt,
# requirements-build.txt, or pin of a ros-* wheel or numpy in constraints.txt triggers a rebuild;
# the files of the previous build are removed first.
set -euo pipefail

die() { echo "build_vision_msgs: $1" >&2; exit "${2:-1}"; }

[ "$#" -eq 1 ] || die "usage: scripts/build_vision_msgs.sh VENV_DIR" 2
[ -x "$1/bin/python" ] || die "'$1' is not a virtual environment (no $1/bin/python)" 2
venv="$(cd "$1" && pwd)"
py="$venv/bin/python"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
src="$root/interfaces/vision_msgs"
reqs="$root/interfaces/requirements-build.txt"
[ -f "$src/package.xml" ] || die "interface sources not found: $src/package.xml"

# Where the wheels were built; their exported CMake files hard-code these include paths.
wheel_py_prefix="/opt/python/cp311-cp311"

stamp="$venv/share/vision_msgs/.iemd_sources.sha256"
manifest="$venv/share/vision_msgs/.iemd_install_manifest.txt"

works() {
  # Importing the generated Python module is not enough: also load its C type support.
  "$py" -c 'from vision_msgs.msg import Detection2DArray as M
M.__class__.__import_type_support__()' \
    >/dev/null 2>&1
}

want="$(
  cd "$src"
  { find . -type f \( -name '*.msg' -o -name package.xml -o -name CMakeLists.txt \) -print0 \
      | LC_ALL=C sort -z | xargs -0 sha256sum
    sha256sum < "$reqs"
    # The ROS wheels and NumPy it is compiled against (not the rest of constraints.txt).
    { grep -iE '^(ros-|numpy==)' "$root/constraints.txt" || true; } | LC_ALL=C sort
  } | sha256sum | cut -d' ' -f1
)"

if [ -f "$stamp" ]; then
  if [ "$(cat "$stamp")" = "$want" ] && works; then
    echo "[vision_msgs] up to date in $venv"
    exit 0
  fi
  echo "[vision_msgs] interface sources changed (or previous build broken): rebuilding"
elif works; then
  where="$("$py" -c 'import os, vision_msgs; print(os.path.dirname(vision_msgs.__file__))')"
  echo "[vision_msgs] already provided by $where: nothing to build"
  exit 0
fi

"$py" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' \
  || die "the ROS 2 Jazzy wheels on PyPI are for Python 3.11 only; $py is $("$py" -V 2>&1)"
start=$SECONDS

echo "[vision_msgs] installing build-only wheels (interfaces/requirements-build.txt)"
"$py" -m pip install -q --disable-pip-version-check -r "$reqs" -c "$root/constraints.txt"

# Point the wheels' exported CMake include paths at this machine's Python and NumPy headers.
# Idempotent (nothing left to replace after the first run) and limited to files inside the venv.
pyinc="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
npinc="$("$py" -c 'import numpy; print(numpy.get_include())')"
[ -f "$pyinc/Python.h" ] \
  || die "Python headers not found ($pyinc/Python.h); install the Python 3.11 development headers"
[ -d "$npinc/numpy" ] || die "NumPy headers not found in $npinc"
find_unpatched() {
  grep -rlF --include='*.cmake' "$wheel_py_prefix" "$venv/share" "$venv/lib" 2>/dev/null || true
}
mapfile -t to_patch < <(find_unpatched)
if [ "${#to_patch[@]}" -gt 0 ]; then
  echo "[vision_msgs] patching ${#to_patch[@]} exported CMake files ($wheel_py_prefix -> this venv)"
  sed -i \
    -e "s|$wheel_py_prefix/lib/python3.11/site-packages/numpy/_core/include|$npinc|g" \
    -e "s|$wheel_py_prefix/include/python3.11|$pyinc|g" \
    "${to_patch[@]}"
  left="$(find_unpatched)"
  [ -z "$left" ] || die "unexpected $wheel_py_prefix paths left in: $left"
fi

build="$(mktemp -d "${TMPDIR:-/tmp}/vision_msgs_build.XXXXXX")"
log="$build/build.log"
fail() {
  tail -n 40 "$log" >&2 || true
  die "$1 failed (full log: $log)"
}
# A hermetic build: only this venv's packages, whatever ROS environment the shell has sourced.
cm() {
  env -u AMENT_PREFIX_PATH -u CMAKE_PREFIX_PATH -u PYTHONPATH "$venv/bin/cmake" "$@" >>"$log" 2>&1
}

echo "[vision_msgs] configuring and building in $build"
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

works || die "installed, but vision_msgs.msg.Detection2DArray or its type support fails in $venv"
echo "$want" > "$stamp"
rm -rf "$build"
echo "[vision_msgs] installed into $venv in $((SECONDS - start)) s"
