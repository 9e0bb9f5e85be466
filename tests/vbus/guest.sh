#!/bin/bash
# Second stage of the vbus guest, run by init.sh inside the chroot of the host root after
# it has set up the network. Restores the caller's environment and cwd and execs the
# command, using bash builtins only (each program loaded over 9p costs time under TCG).
# Argument: the exchange dir (same path as on the host).
# Exit 125 (with a message) when the cwd cannot be entered, before the command runs.
x=$1

while IFS= read -r -d '' kv; do
    case ${kv%%=*} in
        BASH_* | BASHOPTS | SHELLOPTS | PWD | OLDPWD | SHLVL | _ | '') ;;
        *) export "$kv" 2>/dev/null ;; # names bash cannot hold are dropped
    esac
done < "$x/env"
export VBUS_GUEST=1 PATH=$VBUS_PATH
unset VBUS_PATH

cmd=()
while IFS= read -r -d '' arg; do cmd+=("$arg"); done < "$x/cmd"
IFS= read -r cwd < "$x/cwd"
cd "$cwd" || { echo "vbus: cannot enter $cwd" >&2; exit 125; }
read -r up _ < /proc/uptime
echo "command $up" >> "$x/timing"
: > "$x/started"
exec "${cmd[@]}"
