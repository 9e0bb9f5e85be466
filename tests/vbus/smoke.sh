#!/usr/bin/env bash
# Smoke test of the vbus guest, run INSIDE it:
#   VBUS_IFACES="vcan0 vcan1:fd" tests/vbus/run.sh tests/vbus/smoke.sh
# Checks kernel CAN traffic (cangen/cansend captured by candump -l: RTR, 29-bit, FD), the
# python peers against python-can/canopen clients, and the peers' command lines against
# raw SDO frames. Prints one line per check and "N passed, N failed"; exits 1 on failure.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
[ "${VBUS_GUEST:-}" = 1 ] || { echo "smoke.sh runs inside the guest: tests/vbus/run.sh $0" >&2; exit 2; }

passed=0
failed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failed=$((failed + 1)); }
has() { grep -qF -- "$2" "$1"; }

work=$(mktemp -d)
cd "$work" || exit 1

# --- raw traffic through the kernel, logged by candump -l ----------------------------
candump -l vcan0 vcan1 2>/dev/null &
dump=$!
sleep 1
cansend vcan0 123#DEADBEEF
cansend vcan0 123#R
cansend vcan0 1ABCDEF0#0102
cansend vcan1 456##1112233445566778899AABBCC
cangen vcan0 -n 20 -g 1 -I 7E0 -L 8 -D i
cangen vcan1 -n 5 -g 1 -f -I 7E1
sleep 0.5
kill -INT $dump
wait $dump
log=$(ls candump-*.log 2>/dev/null | head -1)
if [ -n "$log" ]; then ok "candump -l wrote $log"; else bad "candump -l wrote no log"; log=/dev/null; fi
has "$log" "vcan0 123#DEADBEEF" && ok "classic frame" || bad "classic frame 123#DEADBEEF missing"
has "$log" "vcan0 123#R" && ok "RTR frame" || bad "RTR frame 123#R missing"
has "$log" "vcan0 1ABCDEF0#0102" && ok "29-bit frame" || bad "29-bit frame missing"
grep -qE "vcan1 456##[15]112233445566778899AABBCC" "$log" && ok "CAN FD frame with BRS" || bad "FD frame missing"
n=$(grep -c " vcan0 7E0#" "$log")
[ "$n" = 20 ] && ok "cangen: 20 frames" || bad "cangen: $n frames of 20"
n=$(grep -c " vcan1 7E1##" "$log")
[ "$n" = 5 ] && ok "cangen -f: 5 FD frames" || bad "cangen -f: $n FD frames of 5"

# --- the python peers against python-can/canopen clients, in one interpreter ---------
if python3 "$here/peers/test_peers.py" vcan0 > peers.out 2>&1; then
    ok "peers/test_peers.py ($(tail -1 peers.out))"
else
    cat peers.out
    bad "peers/test_peers.py"
fi

# --- the peers' command lines, spoken to with raw SDO frames -------------------------
python3 "$here/peers/sdo_server.py" vcan0 5 > sdo.out 2>&1 &
sdo_pid=$!
python3 "$here/peers/drive402.py" vcan0 6 > drive.out 2>&1 &
drive_pid=$!
for _ in $(seq 600); do
    has sdo.out "sdo_server ready" && has drive.out "drive402 ready" && break
    sleep 0.1
done
has sdo.out "sdo_server ready vcan0 5" && ok "sdo_server.py ready" || bad "sdo_server.py not ready: $(cat sdo.out)"
has drive.out "drive402 ready vcan0 6" && ok "drive402.py ready" || bad "drive402.py not ready: $(cat drive.out)"

# ask REQUEST on vcan0 and print the first frame with id REPLY_ID
ask() {
    candump -T 5000 -n 1 -L "vcan0,$2:7FF" > reply.out &
    local c=$!
    sleep 0.3
    cansend vcan0 "$1"
    wait $c
    awk '{print $3}' reply.out
}
r=$(ask 605#4000200000000000 585)
[ "$r" = "585#4F00200012000000" ] && ok "sdo_server.py: expedited read 0x2000" || bad "sdo_server.py read: '$r'"
r=$(ask 606#2B40600006000000 586)
[ "$r" = "586#6040600000000000" ] && ok "drive402.py: write controlword 0x0006" || bad "drive402.py write: '$r'"
r=$(ask 606#4041600000000000 586)
[ "$r" = "586#4B41600031020000" ] && ok "drive402.py: statusword 0x0231" || bad "drive402.py statusword: '$r'"
r=$(candump -T 3000 -n 1 -L vcan0,705:7FF | awk '{print $3}')
[ "$r" = "705#7F" ] && ok "sdo_server.py heartbeat" || bad "sdo_server.py heartbeat: '$r'"
kill -TERM $sdo_pid $drive_pid
wait $sdo_pid && wait $drive_pid && ok "peers stop on SIGTERM with status 0" || bad "peers' exit status"

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
