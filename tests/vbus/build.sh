#!/usr/bin/env bash
# Builds (once) the guest kernel and initramfs for the vbus harness and prints the cache
# directory holding them: vmlinux (decompressed, booted through qemu's PVH entry) and
# initrd.cpio (static busybox, init.sh, the CAN/9p/virtio modules in dependency order).
# The cache lives in tests/vbus/cache/, keyed by kernel version and a hash of the files
# that shape the image. VBUS_KERNEL_PKG overrides the Debian kernel package
# (default: what linux-image-amd64 depends on); VBUS_REBUILD=1 forces a rebuild.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cache="$here/cache"
mkdir -p "$cache"
exec 9>"$cache/.lock"
flock 9 # one build at a time; concurrent runs wait for it

# Modules the guest loads; their dependencies are added by modprobe --show-depends.
# kvaser_pci (with sja1000 and can-dev) drives the emulated controllers of VBUS_CAN.
modules=(virtio_pci virtio_mmio virtio_console 9pnet_virtio 9p vcan can_raw can_bcm can_gw kvaser_pci)

resolve_pkg() {
    apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}'
}

pkg=${VBUS_KERNEL_PKG:-}
if [ -z "$pkg" ] && [ -s "$cache/kernel-pkg" ] && [ "${VBUS_REBUILD:-0}" != 1 ]; then
    pkg=$(cat "$cache/kernel-pkg")
fi
if [ -z "$pkg" ]; then
    pkg=$(resolve_pkg)
    if [ -z "$pkg" ]; then
        apt-get update -qq >/dev/null
        pkg=$(resolve_pkg)
    fi
    [ -n "$pkg" ] || { echo "vbus: cannot resolve the kernel package behind linux-image-amd64" >&2; exit 1; }
    echo "$pkg" > "$cache/kernel-pkg"
fi
kver=${pkg#linux-image-}

key=$(cat "$here/build.sh" "$here/init.sh" | sha256sum | cut -c1-12)
out="$cache/$kver-$key"
if [ -f "$out/ok" ] && [ "${VBUS_REBUILD:-0}" != 1 ]; then
    echo "$out"
    exit 0
fi

echo "vbus: building guest image for $kver in $out" >&2
rm -rf "$out"
mkdir -p "$out" "$cache/debs"

# The kernel package, unpacked into the cache: never installed into the host's /boot.
deb=$(ls "$cache/debs/${pkg}_"*.deb 2>/dev/null | head -1 || true)
if [ -z "$deb" ]; then
    (cd "$cache/debs" && apt-get download -q "$pkg" >/dev/null 2>&1) || {
        apt-get update -qq >/dev/null
        (cd "$cache/debs" && apt-get download -q "$pkg" >/dev/null)
    }
    deb=$(ls "$cache/debs/${pkg}_"*.deb | head -1)
fi
kroot="$out/kroot"
dpkg-deb -x "$deb" "$kroot"
depmod -b "$kroot" "$kver"

# Decompress the bzImage payload (xz on Debian amd64) into an ELF vmlinux with a PVH note.
bz="$kroot/boot/vmlinuz-$kver"
off=$(LC_ALL=C grep -obUaP '\xfd7zXZ\x00' "$bz" | head -1 | cut -d: -f1)
[ -n "$off" ] || { echo "vbus: no xz payload in $bz" >&2; exit 1; }
tail -c +$((off + 1)) "$bz" | xz -dc --single-stream > "$out/vmlinux" 2>/dev/null || true
if ! readelf -n "$out/vmlinux" 2>/dev/null | grep -q 'Unknown note type: (0x00000012)'; then
    echo "vbus: $out/vmlinux is not an ELF with a PVH entry note" >&2
    exit 1
fi

# The initramfs tree.
ird="$out/initramfs"
mkdir -p "$ird"/{bin,dev,proc,sys,x,newroot,modules}
cp /bin/busybox "$ird/bin/busybox"
install -m 0755 "$here/init.sh" "$ird/init"
mknod -m 600 "$ird/dev/console" c 5 1
modprobe -d "$kroot" -S "$kver" --show-depends -a "${modules[@]}" |
    awk '$1 == "insmod" && !seen[$2]++ {print $2}' |
    while read -r ko; do
        cp "$ko" "$ird/modules/"
        basename "$ko" >> "$ird/modules/order"
    done
(cd "$ird" && find . | LC_ALL=C sort | /bin/busybox cpio -o -H newc 2>/dev/null) > "$out/initrd.cpio"

rm -rf "$kroot" "$ird"
touch "$out/ok"
for old in "$cache"/[0-9]*-*/; do # images of older keys
    [ "${old%/}" = "$out" ] || rm -rf "$old"
done
echo "$out"
