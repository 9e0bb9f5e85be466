#!/usr/bin/env bash
# Installs what the vbus harness needs; idempotent and silent when everything is present.
#   Debian: qemu-system-x86 busybox-static can-utils iproute2 kmod xz-utils, and for the
#           end-to-end suite (e2e.sh) jq and tmux
#   PyPI:   python-can canopen (into the python3 found on PATH, which the guest also uses)
set -euo pipefail

need_apt=()
command -v qemu-system-x86_64 >/dev/null || need_apt+=(qemu-system-x86)
# The initramfs needs the static busybox: a dynamic one has no libc there.
if ! [ -x /bin/busybox ] || ! dpkg -s busybox-static >/dev/null 2>&1; then need_apt+=(busybox-static); fi
command -v candump >/dev/null || need_apt+=(can-utils)
command -v ip >/dev/null || need_apt+=(iproute2)
command -v modprobe >/dev/null || need_apt+=(kmod)
command -v xz >/dev/null || need_apt+=(xz-utils)
command -v jq >/dev/null || need_apt+=(jq)
command -v tmux >/dev/null || need_apt+=(tmux)

if [ ${#need_apt[@]} -gt 0 ]; then
    echo "vbus: installing ${need_apt[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null
    apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
fi

if ! python3 -c 'import can, canopen' 2>/dev/null; then
    echo "vbus: pip installing python-can canopen" >&2
    python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore python-can canopen >&2
fi
