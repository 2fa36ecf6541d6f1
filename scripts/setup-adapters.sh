#!/usr/bin/env bash
# Creates the virtual environment the reference adapters run in
# (.venv-adapters at the repository root, git-ignored) and installs
# adapters/python/requirements.txt (pybullet 3.2.7, mujoco 4.0.0) and
# adapters/python/requirements-drake.txt (drake 1.51.1 and what it pulls:
# Mosek, matplotlib, ...) into it: binary wheels, no compiler; the two sets
# share numpy and do not conflict, so one venv serves every adapter. About
# 1 minute from an empty pip cache here (Drake's wheel is 42 MB, pybullet's
# 103 MB). Idempotent: a venv whose installed versions already match the pins
# is kept. SKIP_DRAKE=1 installs requirements.txt only.
#
# pure_python.py needs none of this (only python3); pushval.toml runs the
# other adapters with .venv-adapters/bin/python.
#
# Progress goes to stderr. Exit 0 when the venv has every pin; otherwise the
# pip error is printed and the exit status is pip's.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$root/.venv-adapters"
reqs=("$root/adapters/python/requirements.txt")
if [ "${SKIP_DRAKE:-0}" != 1 ]; then
    reqs+=("$root/adapters/python/requirements-drake.txt")
fi
py="${PYTHON:-python3}"
if ! command -v "$py" >/dev/null; then
    echo "setup-adapters: $py not found; install Python 3.9+ (e.g. apt-get install python3 python3-venv)" >&2
    exit 1
fi
if [ ! -x "$venv/bin/python" ]; then
    echo "setup-adapters: creating $venv" >&2
    "$py" -m venv "$venv" >&2
fi
pins="$(cat "${reqs[@]}" | grep -E '^[A-Za-z]' | sort -u)"
# pip freeze spells some names differently (PyYAML, Mosek): compare case-blind.
if "$venv/bin/python" -m pip freeze 2>/dev/null | sort | grep -ixF -f <(echo "$pins") | wc -l \
    | grep -qx "$(echo "$pins" | wc -l)"; then
    echo "setup-adapters: $venv already has $(echo "$pins" | tr '\n' ' ')" >&2
    exit 0
fi
args=()
for r in "${reqs[@]}"; do args+=(-r "$r"); done
echo "setup-adapters: pip install ${args[*]}" >&2
"$venv/bin/python" -m pip install --disable-pip-version-check "${args[@]}" >&2
echo "setup-adapters: ok" >&2
