#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The user-mode Linux kernel the SocketCAN tests boot (tests/can/uml_run.py), in .deps/uml.
#
# Why not Debian 12's own user-mode-linux (6.1): on a host CPU with AMX (its XSAVE area is larger than the
# 4 KiB UML's 6.1 and 6.12 kernels assume), the host refuses UML's ptrace write of the FPU state (EFAULT:
# "userspace - ptrace set fp regs failed, errno = 14") and the guest's init dies at its first instruction.
# UML 7.2 sizes that buffer from the host. It is taken from Debian's unstable pool, with the C library of
# Debian 13 it needs (>= 2.38), both pinned by sha256, unpacked here (nothing is installed system-wide),
# and the kernel's ELF interpreter and library path pointed at that C library (patchelf).
#   scripts/lib/uml.sh            fetch and unpack when missing or when the pins changed (idempotent)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
DEST=$ROOT/.deps/uml
# package  pool path  sha256
UML_DEBS=(
  "user-mode-linux main/u/user-mode-linux/user-mode-linux_7.2um1_amd64.deb f947c9244fd79d481299df2ad68961f6b3b7703bff38c4b0e726f861161da62c"
  "libc6 main/g/glibc/libc6_2.41-12+deb13u5_amd64.deb b59b0625cd1a791375d40dab23a4d5d3d0641e3d0a773501becdc3725b7f99cf"
)
UML_RELEASE=7.2.7 # the kernel's `uname -r`: its modules are under usr/lib/uml/modules/<this>

log() { printf '[setup] %s\n' "$*" >&2; }

stamp_want=$(printf '%s\n' "${UML_DEBS[@]}" | sha256sum | cut -c1-16)
if [ -x "$DEST/linux" ] && [ -d "$DEST/root/usr/lib/uml/modules/$UML_RELEASE" ] &&
   [ "$(cat "$DEST/.stamp" 2>/dev/null)" = "$stamp_want" ]; then
  exit 0
fi

# The Debian mirror this machine's apt already uses.
mirror=$(sed -n 's/^URIs: *//p' /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n 1)
[ -n "$mirror" ] || mirror=$(sed -n 's/^deb \(\[[^]]*\] \)\{0,1\}\([^ ]*\) .*/\2/p' /etc/apt/sources.list 2>/dev/null | head -n 1)
[ -n "$mirror" ] || { log "uml: no Debian mirror in /etc/apt/sources.list*"; exit 1; }
command -v patchelf >/dev/null || { log "uml: patchelf is missing (apt-get install patchelf)"; exit 1; }

log "uml: fetching user-mode Linux $UML_RELEASE and its C library"
mkdir -p "$ROOT/.deps"
work=$(mktemp -d "$ROOT/.deps/uml.part.XXXXXX")
trap 'rm -rf "$work"' EXIT
for entry in "${UML_DEBS[@]}"; do
  read -r name path sha <<<"$entry"
  deb=$work/$(basename "$path")
  curl -fsSL --retry 3 -o "$deb" "${mirror%/}/pool/$path" || { log "uml: could not fetch $name ($path)"; exit 1; }
  got=$(sha256sum "$deb" | cut -d' ' -f1)
  [ "$got" = "$sha" ] || { log "uml: $name has sha256 $got, pinned $sha: refused"; exit 1; }
  dpkg-deb -x "$deb" "$work/root"
  rm -f "$deb"
done
libdir=$DEST/root/usr/lib/x86_64-linux-gnu # where it will be once renamed into place
cp "$work/root/usr/bin/linux.uml" "$work/linux"
patchelf --set-interpreter "$libdir/ld-linux-x86-64.so.2" --set-rpath "$libdir" "$work/linux"
printf '%s\n' "$stamp_want" > "$work/.stamp"
rm -rf "$DEST"
mv "$work" "$DEST"
trap - EXIT
log "uml: $DEST/linux"
