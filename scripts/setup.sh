#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs everything pour needs on Debian 12 (bookworm): apt packages, a pinned Python venv in .venv,
# the Unity test framework in .deps/unity, and ST's descriptions of the STM32G4 (the stm32g4, stm32g4xx-hal
# and stm32-metapac crates, in .deps/stm32g4). Idempotent: a second run checks and changes nothing.
#   ./scripts/setup.sh              all of that
#   ./scripts/setup.sh --build      what the build and the README's commands need: not the three crates nor
#                                   the user-mode Linux kernel, which only the tests use (scripts/build.sh,
#                                   scripts/demo.sh)
#   ./scripts/setup.sh --with-sb3   and the optional Stable-Baselines3 extra in .venv (stable-baselines3 and
#                                   torch from tools/requirements-sb3.lock, about 2.9 GB: pour.examples.sb3_ppo)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"
WITH_SB3=0
WITH_CRATE=1
for arg in "$@"; do
  case "$arg" in
    --with-sb3) WITH_SB3=1 ;;
    --build) WITH_CRATE=0 ;;
    *) echo "setup.sh: unknown argument '$arg' (see --help)" >&2; exit 2 ;;
  esac
done

log() { printf '[setup] %s\n' "$*" >&2; }

# Debian 12 packages. Versions are those of the bookworm release (and its security updates).
APT_PACKAGES=(
  cmake ninja-build gcc g++ make pkgconf git
  clang-14 libclang-rt-14-dev llvm-14
  libeigen3-dev
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi qemu-system-arm
  can-utils iproute2 kmod patchelf
  default-jdk-headless default-jre fonts-dejavu-core xvfb xauth x11-apps
  python3 python3-venv python3-dev python3-tk libglib2.0-0
  ca-certificates xz-utils curl
  openocd
)
# The crates' fetch (below): Debian 12's cargo-web, the newer cargo Debian keeps for its browsers' builds
# (1.85 in bookworm, newer in its security updates). The older `cargo` package (0.66, Rust 1.65) cannot
# serve: it reads the registry's index only through a git clone of all of it (its sparse index is behind
# -Z), and it cannot parse stm32-metapac 21.0.0's manifest (edition 2024). cargo-web conflicts with Debian's
# rustup package: where that is installed, its cargo (on PATH) is used instead. POUR_CARGO names another.
if [ "$WITH_CRATE" = 1 ]; then
  if [ -n "${POUR_CARGO:-}" ]; then
    CARGO_BIN=$POUR_CARGO
  elif dpkg-query -W -f='${Status}' rustup 2>/dev/null | grep -q 'install ok installed'; then
    CARGO_BIN=cargo
  else
    APT_PACKAGES+=(cargo-web)
    CARGO_BIN=/usr/bin/cargo
  fi
fi

SUDO=""
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null || { log "not root and no sudo: install ${APT_PACKAGES[*]} by hand"; exit 1; }
  SUDO=sudo
fi

apt_missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || apt_missing+=("$p")
done
if [ ${#apt_missing[@]} -gt 0 ]; then
  log "apt: installing ${apt_missing[*]}"
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${apt_missing[@]}" >/dev/null
fi

# Python: Debian's interpreter, so a fresh machine and CI run the same one.
PY=/usr/bin/python3
if [ ! -x .venv/bin/python ]; then
  log "venv: creating .venv"
  "$PY" -m venv .venv
fi
stamp_want=$(cat tools/requirements.lock tools/pyproject.toml | sha256sum | cut -c1-16)
if [ "$(cat .venv/.pour-stamp 2>/dev/null)" != "$stamp_want" ]; then
  log "venv: installing tools/requirements.lock"
  # Every file checked against the lock's sha256 (pip refuses an unpinned or unhashed package).
  .venv/bin/python -m pip install -q --disable-pip-version-check --require-hashes -r tools/requirements.lock
  # The build runs in the venv (setuptools, wheel and lcm from the lock): nothing unpinned is fetched for it.
  .venv/bin/python -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e tools
  # A wheel carries the start-up hook that registers the Gymnasium ids (tools/setup.py); an editable install
  # does not, so the same file goes into the venv's site-packages here.
  cp tools/_pour_gymnasium.pth "$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/"
  echo "$stamp_want" > .venv/.pour-stamp
fi
if [ "$WITH_SB3" = 1 ]; then
  sb3_want=$(cat tools/requirements.lock tools/requirements-sb3.lock | sha256sum | cut -c1-16)
  if [ "$(cat .venv/.pour-sb3-stamp 2>/dev/null)" != "$sb3_want" ]; then
    log "venv: installing tools/requirements-sb3.lock (Stable-Baselines3, torch)"
    # Both locks at once, so that pip checks the extra's pins against the main lock's.
    .venv/bin/python -m pip install -q --disable-pip-version-check --require-hashes \
      -r tools/requirements.lock -r tools/requirements-sb3.lock
    echo "$sb3_want" > .venv/.pour-sb3-stamp
  fi
fi

# Unity 2.5 (ThrowTheSwitch), as carried in Debian's ntpsec source package, pinned by hash.
UNITY_DIR=.deps/unity
UNITY_TARBALL=ntpsec_1.2.2+dfsg1.orig.tar.xz
UNITY_TARBALL_SHA256=53e527e3d04d551d41af2d359c2715c2de5f5bfa2a695d4ec1a811b3e9137f63
if [ ! -f "$UNITY_DIR/unity.c" ]; then
  log "unity: fetching Debian source package ntpsec"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  mkdir -p "$work/parts" "$work/lists/partial" "$work/cache/archives/partial"
  # deb-src entry derived from the system's own sources, in a private apt state: nothing global changes.
  for f in /etc/apt/sources.list.d/*.sources; do
    if [ -f "$f" ]; then sed 's/^Types: deb$/Types: deb-src/' "$f" > "$work/parts/$(basename "$f")"; fi
  done
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    if [ -f "$f" ]; then sed -n 's/^deb \(.*\)$/deb-src \1/p' "$f" >> "$work/parts/src.list"; fi
  done
  aptopts=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$work/parts"
           -o "Dir::State::Lists=$work/lists" -o "Dir::Cache=$work/cache" -o APT::Sandbox::User=root)
  apt-get "${aptopts[@]}" update -qq
  (cd "$work" && apt-get "${aptopts[@]}" source --download-only -qq ntpsec >/dev/null 2>&1)
  echo "$UNITY_TARBALL_SHA256  $work/$UNITY_TARBALL" | sha256sum -c --quiet - \
    || { log "unity: $UNITY_TARBALL does not match its pinned hash"; exit 1; }
  mkdir -p "$UNITY_DIR"
  tar -xJf "$work/$UNITY_TARBALL" -C "$UNITY_DIR" --strip-components=3 \
    --wildcards '*/tests/unity/unity.c' '*/tests/unity/unity.h' '*/tests/unity/unity_internals.h'
fi

# ST's register description of the STM32G4 (the stm32g4 crate: stm32-rs's svd2rust output of ST's SVD
# files), which tests/board/check_registers.py compares the port's register tables with; the stm32g4xx-hal
# crate, whose pin maps (generated from ST's STM32CubeMX database) it checks the board's alternate functions
# against; and the stm32-metapac crate, ST's CubeMX pin data per package (src/chips/stm32g431cb/), for the
# board's pin check. cargo fetches them from the crate registry through its sparse index (no git index),
# with every transitive dependency pinned by scripts/crates/Cargo.toml, into a private CARGO_HOME
# (.deps/cargo); nothing is built. Each .crate file is then checked against its sha256 pinned here (ours, on
# top of cargo's own check against the index) and unpacked under .deps/stm32g4/NAME-VERSION by
# scripts/lib/unpack_crate.py; never copied into the repo. The marker files crate-dir, hal-dir and
# metapac-dir hold each unpacked crate's absolute path; NAME-VERSION.sha256 records the pin it was checked
# against, so a changed pin unpacks again.
SVD_CRATES=("stm32g4 0.16.0 97bc6434066d2459f0e0834ade8b03e5c5e8d4aad84dc2ff50e56464e6104f4d crate-dir src/stm32g431/mod.rs"
            "stm32g4xx-hal 0.1.0 6402921e7994d834b5717593270b821dfb601d83ea7eeb4ebd6b2b3fe730f793 hal-dir src/pwm.rs"
            "stm32-metapac 21.0.0 e74b78632cea498cfb28386a29f8bfae7476d6570a78733eb5fecbee66c2f4ce metapac-dir src/chips/stm32g431cb/pac.rs")
SVD_WORK=$ROOT/.deps/stm32g4
CARGO_WORK=$ROOT/.deps/cargo
if [ "$WITH_CRATE" = 1 ]; then
  mkdir -p "$SVD_WORK"
  fetched=0
  for entry in "${SVD_CRATES[@]}"; do
    read -r name ver sha marker probe <<<"$entry"
    dir=$SVD_WORK/$name-$ver
    if [ "$(cat "$SVD_WORK/$marker" 2>/dev/null)" = "$dir" ] && [ -f "$dir/$probe" ] \
       && [ "$(cat "$SVD_WORK/$name-$ver.sha256" 2>/dev/null)" = "$sha" ]; then
      continue
    fi
    if [ "$fetched" = 0 ]; then
      command -v "$CARGO_BIN" >/dev/null || { log "crates: no cargo '$CARGO_BIN' (see the apt list's comment)"; exit 1; }
      log "crates: fetching scripts/crates/Cargo.toml's dependencies from the crate registry ($($CARGO_BIN --version))"
      # A copy of the manifest, so that the lock file cargo writes beside it stays out of the checkout.
      mkdir -p "$CARGO_WORK/manifest/src"
      cp scripts/crates/Cargo.toml "$CARGO_WORK/manifest/Cargo.toml"
      cp scripts/crates/src/lib.rs "$CARGO_WORK/manifest/src/lib.rs"
      rustc_env=()
      [ "$CARGO_BIN" = /usr/bin/cargo ] && rustc_env=(RUSTC=/usr/bin/rustc)  # Debian's, beside its cargo
      env "${rustc_env[@]}" CARGO_HOME="$CARGO_WORK/home" "$CARGO_BIN" fetch -q \
        --manifest-path "$CARGO_WORK/manifest/Cargo.toml" || { log "crates: cargo fetch failed"; exit 1; }
      fetched=1
    fi
    shopt -s nullglob
    crates=("$CARGO_WORK"/home/registry/cache/*/"$name-$ver.crate")
    shopt -u nullglob
    [ ${#crates[@]} = 1 ] || { log "crates: cargo's cache holds ${#crates[@]} files $name-$ver.crate, not one"; exit 1; }
    # cargo keeps a cached .crate file without checking it again: a refused one is removed with its cache.
    got=$("$PY" scripts/lib/unpack_crate.py "$name" "$ver" "$sha" "${crates[0]}" "$SVD_WORK") \
      || { log "crates: $name $ver refused; removing .deps/cargo, so that the next run fetches afresh"
           rm -rf "$CARGO_WORK"; exit 1; }
    [ "$got" = "$dir" ] && [ -f "$dir/$probe" ] || { log "crates: no $probe under '$got'"; exit 1; }
    echo "$sha" > "$SVD_WORK/$name-$ver.sha256.part" && mv "$SVD_WORK/$name-$ver.sha256.part" "$SVD_WORK/$name-$ver.sha256"
    echo "$dir" > "$SVD_WORK/$marker.part" && mv "$SVD_WORK/$marker.part" "$SVD_WORK/$marker"
  done
fi

# The user-mode Linux kernel of the SocketCAN tests (scripts/lib/uml.sh says why not Debian 12's): the tests
# only, as the crates.
if [ "$WITH_CRATE" = 1 ]; then
  scripts/lib/uml.sh
fi

log "ok"
