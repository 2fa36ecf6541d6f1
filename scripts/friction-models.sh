#!/usr/bin/env bash
# Regenerates results/friction_models/: the rapier3d and MuJoCo studies first
# (MuJoCo only when scripts/setup-mujoco.sh can provide libmujoco.so), then the
# 2-D idioms, whose README.md also gathers the other two.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --locked -p pushval-rapier3d --example friction_models_3d
if eval "$(scripts/setup-mujoco.sh)"; then
    cargo run --release --locked -p pushval-mujoco --features mujoco --example friction_models_mujoco
else
    echo "friction-models.sh: MuJoCo unavailable; keeping results/friction_models/mujoco/ as it is" >&2
fi
cargo run --release --locked -p pushval-rapier --example friction_models
