#!/bin/busybox sh
# PID 1 of the vbus guest (runs from the initramfs, busybox only).
# Loads the modules, mounts the exchange share (tag vbus.x) and the host root (tag
# vbus.root, read-only), prepares the chroot and runs the harness's guest.sh in it with
# stdout/stderr on the virtio ports vbus.out/vbus.err. Writes the exit status to
# /x/status (124 on timeout) and powers off (qemu exits). Any failure here leaves no
# status, which the host reports as a boot failure (125) with the console log. A kernel
# panic reboots, and qemu runs with -no-reboot, so it exits then too.
/bin/busybox --install -s /bin
export PATH=/bin

fail() {
    echo "vbus-init: $*" >/dev/console
    sync; poweroff -f
}

mount -t proc proc /proc
# The host's KVM probe boots with vbus.probe: answer on the console and stop.
case " $(cat /proc/cmdline) " in *" vbus.probe "*) echo vbus-probe-ok >/dev/console; sync; poweroff -f ;; esac
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
for m in $(cat /modules/order); do
    insmod "/modules/$m" || fail "insmod $m failed"
done

opts=trans=virtio,version=9p2000.L,msize=512000
mount -t 9p -o "$opts" vbus.x /x || fail "cannot mount the exchange share"
. /x/config || fail "cannot read /x/config"
# Guest uptime at each stage, for VBUS_TIMING.
stamp() { echo "$1 $(cut -d' ' -f1 /proc/uptime)" >> /x/timing; }
stamp modules+exchange

r=/newroot
mount -t 9p -o "ro,$opts,cache=loose" vbus.root $r || fail "cannot mount the host root"
mount -t proc proc $r/proc
mount -t sysfs sys $r/sys
mount -t devtmpfs dev $r/dev
mkdir -p $r/dev/pts $r/dev/shm
ln -s /proc/self/fd $r/dev/fd
ln -s /proc/self/fd/0 $r/dev/stdin
ln -s /proc/self/fd/1 $r/dev/stdout
ln -s /proc/self/fd/2 $r/dev/stderr
mount -t devpts devpts $r/dev/pts
mount -t tmpfs shm $r/dev/shm
# Fresh writable /tmp, /run and /var/tmp; the host entries holding the cwd and the harness
# (a clone in /tmp, say) are bound back in, read-only, from a plain view of the root.
mkdir -p /hostroot
mount --bind $r /hostroot
for d in /tmp /run /var/tmp; do
    [ -d $r$d ] && mount -t tmpfs -o mode=1777 tmp $r$d
done
shown=" "
for p in $VBUS_SHOW; do
    for d in /tmp /run /var/tmp; do
        case $p in
            $d/*)
                rest=${p#$d/}
                top=$d/${rest%%/*}
                case $shown in *" $top "*) continue ;; esac
                shown="$shown$top "
                mkdir -p $r$top
                mount --bind /hostroot$top $r$top || fail "cannot show $top in the guest"
                ;;
        esac
    done
done
mkdir -p "$r$VBUS_XDIR" 2>/dev/null
mount --bind /x "$r$VBUS_XDIR" || fail "cannot mount the exchange dir at $VBUS_XDIR"
# Extra writable shares: lines "TAG PATH".
while read -r tag path; do
    [ -n "$tag" ] || continue
    mkdir -p "$r$path" 2>/dev/null
    mount -t 9p -o "$opts" "$tag" "$r$path" || fail "cannot mount $tag at $path"
done < /x/rw

stamp mounts
# Network: lo and the vcan interfaces (busybox ip: no host binary to load over 9p).
ip link set lo up || fail "cannot bring up lo"
for spec in $VBUS_IFACES; do
    name=${spec%%:*}
    ip link add dev "$name" type vcan || fail "cannot create $name"
    case $spec in
        *:fd) ip link set "$name" mtu 72 || fail "cannot set MTU 72 (CAN FD) on $name" ;;
        "$name") ;;
        *) fail "unknown option in VBUS_IFACES entry '$spec' (known: NAME, NAME:fd)" ;;
    esac
    ip link set "$name" up || fail "cannot bring up $name"
done
stamp network

port() {
    for p in /sys/class/virtio-ports/*; do
        [ "$(cat "$p/name" 2>/dev/null)" = "$1" ] && { echo "/dev/${p##*/}"; return; }
    done
    fail "no virtio port $1"
}
out=$(port vbus.out)
err=$(port vbus.err)

# A virtio port opens only once, so the command writes into FIFOs drained by cat: it may
# then reopen /dev/stdout or /dev/stderr, and the timeout path can still report.
mkfifo /o /e
cat /o >"$out" &
cat_out=$!
cat /e >"$err" &
cat_err=$!

(
    sleep "$VBUS_TIMEOUT"
    echo "vbus: command timed out after ${VBUS_TIMEOUT}s" >/e
    echo 124 > /x/status
    sleep 0.3
    sync; poweroff -f
) &

chroot $r /bin/bash "$VBUS_GUEST_SCRIPT" "$VBUS_XDIR" </dev/null >/o 2>/e
rc=$?
# The readers end once no writer is left; a background process the command left running
# may hold one open, so wait for them at most 2 s.
i=0
while [ $i -lt 20 ] && { kill -0 $cat_out || kill -0 $cat_err; } 2>/dev/null; do
    sleep 0.1
    i=$((i + 1))
done
echo $rc > /x/status
sync; poweroff -f
