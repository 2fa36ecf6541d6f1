#!/usr/bin/env bash
# Opt-in: MuJoCo Warp 4.0 on the CPU beside MuJoCo C 4.0, in its own virtual
# environment .venv-warp (git-ignored), for adapters/python/mujoco_warp_push.py
# (engines mujoco_warp_elliptic / mujoco_warp_pyramidal in pushval.toml) and
# scripts/compare_mujoco_warp.py. Not part of CI's default run. pip only: the
# wheels carry Warp's CPU compiler; the first run compiles MuJoCo Warp's
# kernels (minutes) into Warp's kernel cache.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv-warp
.venv-warp/bin/python -m pip install --disable-pip-version-check -q \
    mujoco==4.0.0 mujoco-warp==4.0.0 warp-lang==1.19.0 numpy==2.4.6
.venv-warp/bin/python -c "import mujoco, mujoco_warp, warp; print('mujoco', mujoco.__version__, 'warp', warp.__version__)"
