#!/usr/bin/env bash
# Creates the virtual environment the reference adapters run in
# (.venv-adapters at the repository root, git-ignored) and installs
# adapters/python/requirements.txt into it (pybullet 3.2.7, mujoco 4.0.0:
# both binary wheels, no compiler). Idempotent: a venv whose installed
# versions already match the pins is kept.
#
# pure_python.py needs none of this (only python3); pushval.toml runs the
# other adapters with .venv-adapters/bin/python.
#
# Progress goes to stderr. Exit 0 when the venv has every pin; otherwise the
# pip error is printed and the exit status is pip's.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$root/.venv-adapters"
req="$root/adapters/python/requirements.txt"
py="${PYTHON:-python3}"
if ! command -v "$py" >/dev/null; then
    echo "setup-adapters: $py not found; install Python 3.9+ (e.g. apt-get install python3 python3-venv)" >&2
    exit 1
fi
if [ ! -x "$venv/bin/python" ]; then
    echo "setup-adapters: creating $venv" >&2
    "$py" -m venv "$venv" >&2
fi
if "$venv/bin/python" -m pip freeze 2>/dev/null | sort | grep -xF -f <(grep -E '^[A-Za-z]' "$req" | sort) | wc -l \
    | grep -qx "$(grep -cE '^[A-Za-z]' "$req")"; then
    echo "setup-adapters: $venv already has $(grep -E '^[A-Za-z]' "$req" | tr '\n' ' ')" >&2
    exit 0
fi
echo "setup-adapters: pip install -r $req" >&2
"$venv/bin/python" -m pip install --disable-pip-version-check -r "$req" >&2
echo "setup-adapters: ok" >&2
