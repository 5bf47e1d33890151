#!/usr/bin/env bash
# Create or refresh .venv/ in the repository root with every dependency and the
# project itself installed (not only importable from the tree).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
venv="$root/.venv"
py="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
  echo "[setup] creating $venv"
  "$py" -m venv "$venv"
fi
stamp="$venv/.requirements.sha256"
want="$(cat requirements.txt constraints.txt | sha256sum | cut -d' ' -f1)"
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "[setup] installing pinned dependencies (requirements.txt, constraints.txt)"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r requirements.txt -c constraints.txt
  echo "$want" > "$stamp"
fi
# vision_msgs, tf2_msgs and foxglove_msgs have no PyPI wheel: build the vendored
# interfaces into the venv (no-op when up to date or a ROS install provides them).
bash "$root/scripts/build_interfaces.sh" "$venv"
echo "[setup] installing iemd_ros into $venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --no-deps --force-reinstall --no-build-isolation .
# numba's cache beside the installed package: the first start of the node or iemd-replay compiles nothing
(cd / && "$venv/bin/iemd-compile")
