#!/usr/bin/env bash
# Installs MuJoCo 3.17.0's shared library for the `mujoco` feature (crate
# pushval-mujoco, which binds it through mujoco-rs 7.0.0+mj-3.17.0).
#
# It fetches the PyPI wheel mujoco==3.17.0 with pip, checks its sha256 (pinned
# for x86_64 Linux), extracts only libmujoco.so.3.17.0 into
# .mujoco/mujoco-3.17.0/lib/ (git-ignored), and adds the libmujoco.so link
# the linker looks for. No headers, nothing else. Idempotent: a library that
# is already there with the pinned sha256 is kept and nothing is downloaded.
#
# Progress goes to stderr; stdout holds only the two exports, so
#
#     eval "$(scripts/setup-mujoco.sh)"
#     CARGO_TARGET_DIR=... cargo test --release -p pushval-mujoco --features mujoco
#
# sets up a shell. MUJOCO_DYNAMIC_LINK_DIR is what mujoco-rs's build script
# reads (an absolute path to a lib/ folder holding libmujoco.so). The
# pushval-mujoco build script also writes that folder into the rpath of the
# crate's tests and examples, so they run without LD_LIBRARY_PATH; other
# binaries linking the crate (the pushval CLI with `--features mujoco`) need
# the LD_LIBRARY_PATH export.
#
# Options: --env  print the exports only (same as no option; kept for
#                 `source <(scripts/setup-mujoco.sh --env)`)
#          --check  exit 0 when the library is installed, 1 otherwise; no download.
set -euo pipefail

VERSION=3.17.0
# PyPI wheel for CPython 3.11 on x86_64 manylinux_2_28 and the library inside it.
WHEEL_X86_64=mujoco-3.17.0-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl
WHEEL_X86_64_SHA256=d66928d86a2d1b601bbaa4dc11db50214d17d5301bb8afd84721313b67ff0874
LIB_X86_64_SHA256=23496b023ee80fb61ab71167e94bc649f9941710fde96b18bb8204fb332523ad

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
libdir="$root/.mujoco/mujoco-$VERSION/lib"
lib="$libdir/libmujoco.so.$VERSION"
arch="$(uname -m)"

mode=install
for arg in "$@"; do
    case "$arg" in
    --env) ;;
    --check) mode=check ;;
    *)
        echo "setup-mujoco.sh: unknown option '$arg' (options: --env, --check)" >&2
        exit 2
        ;;
    esac
done

sha256() { python3 -c 'import hashlib,sys; print(hashlib.sha256(open(sys.argv[1],"rb").read()).hexdigest())' "$1"; }

installed() {
    [[ -f "$lib" && -L "$libdir/libmujoco.so" ]] || return 1
    if [[ "$arch" == x86_64 ]]; then
        [[ "$(sha256 "$lib")" == "$LIB_X86_64_SHA256" ]] || return 1
    fi
}

if [[ "$mode" == check ]]; then
    installed
    exit $?
fi

if installed; then
    echo "setup-mujoco.sh: libmujoco.so.$VERSION already in $libdir" >&2
else
    tmp="$(mktemp -d)"
    trap 'rm -rf "$tmp"' EXIT
    echo "setup-mujoco.sh: downloading the PyPI wheel mujoco==$VERSION (~26 MB)" >&2
    if [[ "$arch" == x86_64 ]]; then
        # Pin the wheel (not the host's Python) so that its sha256 can be checked.
        python3 -m pip download "mujoco==$VERSION" --no-deps --only-binary=:all: \
            --platform manylinux_2_28_x86_64 --python-version 3.11 \
            --implementation cp --abi cp311 -d "$tmp" >&2
        wheel="$tmp/$WHEEL_X86_64"
        [[ -f "$wheel" ]] || {
            echo "setup-mujoco.sh: pip did not produce $WHEEL_X86_64" >&2
            exit 1
        }
        got="$(sha256 "$wheel")"
        if [[ "$got" != "$WHEEL_X86_64_SHA256" ]]; then
            echo "setup-mujoco.sh: sha256 mismatch for $WHEEL_X86_64: $got (expected $WHEEL_X86_64_SHA256)" >&2
            exit 1
        fi
    else
        echo "setup-mujoco.sh: warning: no pinned sha256 for $arch; using the wheel pip picks" >&2
        python3 -m pip download "mujoco==$VERSION" --no-deps --only-binary=:all: -d "$tmp" >&2
        wheel="$(ls "$tmp"/mujoco-"$VERSION"-*.whl | head -n 1)"
    fi
    mkdir -p "$libdir"
    # A wheel is a zip; `unzip` may be missing, python3's zipfile is not.
    python3 - "$wheel" "$lib.part" "$VERSION" <<'EOF'
import shutil, sys, zipfile
wheel, out, version = sys.argv[1:4]
with zipfile.ZipFile(wheel) as z, z.open(f"mujoco/libmujoco.so.{version}") as src, open(out, "wb") as dst:
    shutil.copyfileobj(src, dst)
EOF
    if [[ "$arch" == x86_64 && "$(sha256 "$lib.part")" != "$LIB_X86_64_SHA256" ]]; then
        echo "setup-mujoco.sh: sha256 mismatch for the extracted libmujoco.so.$VERSION" >&2
        rm -f "$lib.part"
        exit 1
    fi
    chmod 0755 "$lib.part"
    mv -f "$lib.part" "$lib"
    ln -sfn "libmujoco.so.$VERSION" "$libdir/libmujoco.so"
    echo "setup-mujoco.sh: installed $lib" >&2
fi

echo "export MUJOCO_DYNAMIC_LINK_DIR=$libdir"
echo "export LD_LIBRARY_PATH=$libdir\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
