#!/bin/bash
# Second stage of the vbus guest, run by init.sh inside the chroot of the host root.
# Restores the caller's environment and cwd, brings up the vcan interfaces and execs the
# command. Arguments: the exchange dir (same path as on the host).
# Exit 125 (with a message) when the setup fails, before the command runs.
x=$1

while IFS= read -r -d '' kv; do
    case ${kv%%=*} in
        BASH_* | BASHOPTS | SHELLOPTS | PWD | OLDPWD | SHLVL | _ | '') ;;
        *) export "$kv" ;;
    esac
done < "$x/env"
export VBUS_GUEST=1 PATH=$VBUS_PATH
unset VBUS_PATH

fail() {
    echo "vbus: $*" >&2
    exit 125
}

ip link set lo up || fail "cannot bring up lo"
for spec in ${VBUS_IFACES:-vcan0}; do
    name=${spec%%:*}
    ip link add dev "$name" type vcan || fail "cannot create $name"
    case $spec in
        *:fd) ip link set "$name" mtu 72 || fail "cannot set MTU 72 (CAN FD) on $name" ;;
        "$name") ;;
        *) fail "unknown option in VBUS_IFACES entry '$spec' (known: NAME or NAME:fd)" ;;
    esac
    ip link set "$name" up || fail "cannot bring up $name"
done

cmd=()
while IFS= read -r -d '' arg; do cmd+=("$arg"); done < "$x/cmd"
cd "$(cat "$x/cwd")" || fail "cannot enter $(cat "$x/cwd")"
echo "command $(cut -d' ' -f1 /proc/uptime)" >> "$x/timing"
: > "$x/started"
exec "${cmd[@]}"
