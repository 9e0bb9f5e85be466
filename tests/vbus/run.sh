#!/usr/bin/env bash
# Runs a command inside a qemu guest that has a real kernel CAN stack (vcan, can-raw,
# can-bcm, can-gw), with the host root shared read-only as the guest's root. See README.md.
#
#   tests/vbus/run.sh CMD [ARG...]
#
# Environment:
#   VBUS_IFACES   interfaces to create (default "vcan0"); "NAME:fd" sets MTU 72 (CAN FD)
#   VBUS_TIMEOUT  seconds the command may run in the guest (default 300)
#   VBUS_OUT      host dir shared writable at the same path in the guest (created if missing)
#   VBUS_RW       more host dirs (space separated) shared writable at the same path
#   VBUS_ACCEL    auto (default: KVM when it boots a guest, else TCG), kvm or tcg
#   VBUS_SMP, VBUS_MEM   guest CPUs (default 2) and memory in MiB (default 1024)
#   VBUS_TIMING=1 print boot-to-command and total time on stderr
#   VBUS_CONSOLE  file to keep the guest's kernel console log in
#   VBUS_KCMD     replaces the kernel's log options (default "quiet loglevel=3")
#
# Exit status: the command's; 124 when it timed out in the guest; 125 when the guest could
# not be started or set up (the reason and the console log tail go to stderr).
set -uo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

if [ $# -eq 0 ]; then
    sed -n '2,/^$/s/^# \{0,1\}//p' "$0" >&2
    exit 2
fi

die() {
    echo "vbus: $*" >&2
    exit 125
}

"$here/install.sh" || die "installing the harness's packages failed"
img=$("$here/build.sh") || die "building the guest image failed"

timeout_s=${VBUS_TIMEOUT:-300}
case $timeout_s in '' | *[!0-9]*) die "VBUS_TIMEOUT must be whole seconds, got '$timeout_s'" ;; esac

tmp=$(mktemp -d /tmp/vbus.XXXXXX) || die "mktemp failed"
x="$tmp/x"
mkdir -p "$x"
qpid=
readers=
# The FIFO readers below end when qemu closes the FIFOs; if qemu never opened them (it
# failed, or the script stopped before starting it), a read-write open (which does not
# block) and close releases them.
release_fifos() {
    local f
    for f in "$tmp/out" "$tmp/err"; do
        [ -p "$f" ] || continue
        exec 7<>"$f"
        exec 7>&-
    done
}
cleanup() {
    [ -n "$qpid" ] && kill "$qpid" 2>/dev/null
    release_fifos
    # A reader that had not yet opened its FIFO when the script failed would wait forever.
    [ -n "$readers" ] && kill $readers 2>/dev/null
    wait 2>/dev/null
    [ -n "${VBUS_CONSOLE:-}" ] && cp "$tmp/console.log" "$VBUS_CONSOLE" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# What the guest needs to know.
{
    printf 'VBUS_XDIR=%q\n' "$x"
    printf 'VBUS_GUEST_SCRIPT=%q\n' "$here/guest.sh"
    printf 'VBUS_TIMEOUT=%q\n' "$timeout_s"
    printf 'VBUS_IFACES=%q\n' "${VBUS_IFACES:-vcan0}"
    # Host paths the guest must see even under its fresh /tmp, /run and /var/tmp.
    printf 'VBUS_SHOW=%q\n' "$(pwd -P) $here"
} > "$x/config"
# A pyenv shim is a shell script that costs seconds per call under TCG: put the directory
# of the interpreter it resolves to (here, on the host) first on the guest's PATH.
py_dir=$(python3 -c 'import os, sys; print(os.path.dirname(sys.executable))' 2>/dev/null || true)
VBUS_PATH=${py_dir:+$py_dir:}$PATH PYTHONDONTWRITEBYTECODE=1 env -0 > "$x/env"
printf '%s\0' "$@" > "$x/cmd"
pwd > "$x/cwd"

# pci=noacpi: PCI interrupt routing from the MP table; ACPI's interrupt links cost about
# 0.25 s per device under TCG.
kextra="pci=noacpi i8042.noaux i8042.nokbd i8042.nopnp"

# Writable shares besides the exchange dir.
rw_args=()
: > "$x/rw"
n=0
for d in ${VBUS_OUT:-} ${VBUS_RW:-}; do
    mkdir -p "$d" || die "cannot create $d"
    d=$(cd "$d" && pwd -P)
    n=$((n + 1))
    rw_args+=(-fsdev "local,id=rw$n,path=$d,security_model=none"
        -device "virtio-9p-pci,fsdev=rw$n,mount_tag=vbus.rw$n")
    printf 'vbus.rw%s %s\n' "$n" "$d" >> "$x/rw"
done

# VBUS_CAN=N: N emulated Kvaser PCI controllers (SJA1000, driver kvaser_pci) on one qemu
# CAN bus, can0..can(N-1) in the guest: real controllers with a bit rate and error
# counters, down until the command sets a bit rate (`ip link set can0 type can bitrate R`).
can_args=()
if [ "${VBUS_CAN:-0}" -gt 0 ]; then
    can_args+=(-object can-bus,id=vbuscan)
    # The controllers have I/O-port BARs, which conflict with the host bridge's ACPI
    # windows under pci=noacpi: PCI routing by ACPI then (slower boot, working BARs).
    kextra=${kextra/pci=noacpi /}
    for _ in $(seq "$VBUS_CAN"); do
        can_args+=(-device kvaser_pci,canbus=vbuscan)
    done
fi

# The command's stdout/stderr come back through virtio ports into FIFOs read here, so
# they stream live to whatever this script's stdout/stderr are.
mkfifo "$tmp/out" "$tmp/err"
cat "$tmp/out" &
readers=$!
cat "$tmp/err" >&2 &
readers="$readers $!"

kvm_usable() {
    [ -r /dev/kvm ] && [ -w /dev/kvm ] || return 1
    local probe="$here/cache/kvm-probe"
    if [ ! -f "$probe" ]; then
        # A stock kernel must actually boot under this KVM: some hosts expose a /dev/kvm
        # that opens but cannot run one. Probe once with a boot that powers off at once.
        (timeout 20 qemu-system-x86_64 -M pc -accel kvm -cpu host -m 256 -nodefaults \
            -no-user-config -display none -no-reboot -kernel "$img/vmlinux" -initrd "$img/initrd.cpio" \
            -append "console=ttyS0 quiet panic=-1 rdinit=/init vbus.probe" -serial "file:$tmp/probe.log" \
            </dev/null >/dev/null 2>&1; true) 2>/dev/null
        if grep -q vbus-probe-ok "$tmp/probe.log" 2>/dev/null; then
            echo yes > "$probe"
        else
            echo no > "$probe"
        fi
    fi
    [ "$(cat "$probe")" = yes ]
}

case ${VBUS_ACCEL:-auto} in
    auto) if kvm_usable; then accel=kvm; else accel=tcg; fi ;;
    kvm | tcg) accel=$VBUS_ACCEL ;;
    *) die "VBUS_ACCEL must be auto, kvm or tcg" ;;
esac
if [ "$accel" = kvm ]; then
    accel_args=(-accel kvm -cpu host)
else
    accel_args=(-accel tcg,thread=multi -cpu max)
fi

t0=$(date +%s.%N)
# Host-side backstop: the guest enforces VBUS_TIMEOUT itself; this only catches a hung boot.
timeout --kill-after=5 $((timeout_s + ${VBUS_BOOT_ALLOWANCE:-90})) \
    qemu-system-x86_64 -M pc "${accel_args[@]}" -smp "${VBUS_SMP:-2}" -m "${VBUS_MEM:-1024}" \
    -nodefaults -no-user-config -display none -no-reboot \
    -kernel "$img/vmlinux" -initrd "$img/initrd.cpio" \
    -append "console=ttyS0 ${VBUS_KCMD:-quiet loglevel=3} panic=-1 rdinit=/init tsc=reliable no_timer_check $kextra" \
    -serial "file:$tmp/console.log" \
    -fsdev "local,id=root,path=/,readonly=on,security_model=none,multidevs=remap" \
    -device virtio-9p-pci,fsdev=root,mount_tag=vbus.root \
    -fsdev "local,id=x,path=$x,security_model=none" \
    -device virtio-9p-pci,fsdev=x,mount_tag=vbus.x \
    "${rw_args[@]}" "${can_args[@]}" \
    -device virtio-serial-pci \
    -chardev "file,id=out,path=$tmp/out" -device virtserialport,chardev=out,name=vbus.out \
    -chardev "file,id=err,path=$tmp/err" -device virtserialport,chardev=err,name=vbus.err \
    </dev/null 2>"$tmp/qemu.err" &
qpid=$!
wait "$qpid"
qrc=$?
qpid=
t1=$(date +%s.%N)
release_fifos
wait

if [ "${VBUS_TIMING:-0}" = 1 ]; then
    if [ -f "$x/started" ]; then
        ts=$(stat -c %.Y "$x/started")
        awk -v a="$t0" -v b="$ts" -v c="$t1" -v acc="$accel" \
            'BEGIN { printf "vbus: %s boot-to-command %.2fs, total %.2fs\n", acc, b - a, c - a }' >&2
        sed 's/^/vbus: guest uptime at /' "$x/timing" >&2
    fi
fi

if [ -s "$x/status" ]; then
    exit "$(cat "$x/status")"
fi
if [ -f "$x/started" ]; then
    echo "vbus: the guest stopped without a status while the command ran (qemu exit $qrc)" >&2
    exit 124
fi
{
    echo "vbus: the guest did not start the command (accel $accel, qemu exit $qrc)"
    [ -s "$tmp/qemu.err" ] && sed 's/^/qemu: /' "$tmp/qemu.err"
    [ -s "$tmp/console.log" ] && tail -n 30 "$tmp/console.log" | sed 's/^/console: /'
} >&2
exit 125
