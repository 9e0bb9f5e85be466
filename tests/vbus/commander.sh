#!/usr/bin/env bash
# The commander over real SocketCAN, run INSIDE the vbus guest (branch vbus):
#   VBUS_IFACES="vcan0" tests/vbus/run.sh tests/vbus/commander.sh [COTUI]
# COTUI defaults to target/debug/cotui of this checkout. A python CiA 402 peer
# (peers/drive402.py) plays node 2; candump logs what really went over the bus.
# Prints one line per check and "N passed, N failed"; exits 1 on failure.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
[ "${VBUS_GUEST:-}" = 1 ] || { echo "commander.sh runs inside the guest: tests/vbus/run.sh $0" >&2; exit 2; }
cotui=$(realpath "${1:-$here/../../target/debug/cotui}")

passed=0
failed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failed=$((failed + 1)); }
json() { python3 -c "import json,sys; d=json.loads(sys.stdin.read() or 'null'); print(eval(sys.argv[1], {'d': d}))" "$1"; }

work=$(mktemp -d)
cd "$work" || exit 1
python3 "${VBUS_PEERS:-$here/peers}/drive402.py" vcan0 2 --heartbeat-ms 200 --tpdo > drive.out 2>&1 &
peer=$!
for _ in $(seq 600); do grep -q "drive402 ready" drive.out && break; sleep 0.1; done
grep -q "drive402 ready vcan0 2" drive.out && ok "peer ready" || bad "peer not ready: $(cat drive.out)"
candump -l vcan0 &
dump=$!
sleep 0.3

out=$("$cotui" sdo read vcan0 2 0x6041 --json); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["value"]')" = 592 ] && ok "sdo read 0x6041 = 0x0250" || bad "sdo read: rc=$rc $out"
out=$("$cotui" sdo read vcan0 2 0x7777 --json); rc=$?
[ $rc = 3 ] && [ "$(echo "$out" | json 'hex(d["abort_code"])')" = 0x6020000 ] && ok "abort exits 3" || bad "abort: rc=$rc $out"
out=$("$cotui" nmt vcan0 start 2 --wait --json); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["confirmed"]["2"]')" = operational ] && ok "nmt start --wait" || bad "nmt: rc=$rc $out"
out=$("$cotui" drive vcan0 2 enable --json); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["state"]')" = operation_enabled ] && ok "drive enable ($(echo "$out" | json 'd["source"]'))" || bad "enable: rc=$rc $out"
out=$("$cotui" drive vcan0 2 quick-stop --json); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["state"]')" = quick_stop_active ] && ok "drive quick-stop" || bad "quick-stop: rc=$rc $out"
out=$("$cotui" drive vcan0 2 disable --json); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["state"]')" = switch_on_disabled ] && ok "drive disable" || bad "disable: rc=$rc $out"
out=$("$cotui" scan vcan0 --json --listen 600); rc=$?
[ $rc = 0 ] && [ "$(echo "$out" | json 'd["nodes"][0]["node"]')" = 2 ] && ok "scan finds node 2" || bad "scan: rc=$rc $out"
out=$("$cotui" record vcan0 -o rec.log --duration 700 --json); rc=$?
[ $rc = 0 ] && grep -q " vcan0 702#05" rec.log && ok "record: heartbeats in candump -l form" || bad "record: rc=$rc $out $(head -3 rec.log)"

sleep 0.3
kill -INT $dump; wait $dump
log=$(ls candump-*.log | head -1)
before=$(grep -c " vcan0 602#" "$log")
candump -l vcan0 & dump=$!
sleep 0.3
"$cotui" sdo read vcan0 2 0x6041 --listen-only --json > lo.out; rc=$?
"$cotui" drive vcan0 2 enable --listen-only > /dev/null 2>&1
"$cotui" nmt vcan0 reset-node 0 --listen-only > /dev/null 2>&1
sleep 0.3
kill -INT $dump; wait $dump
log2=$(ls -t candump-*.log | head -1)
sent=$(grep -c -E " vcan0 (602|000)#" "$log2")
[ $rc = 2 ] && [ "$sent" = 0 ] && ok "listen-only: exit 2 and nothing on the bus (before: $before requests)" || bad "listen-only: rc=$rc sent=$sent"

"$cotui" scan vcan9 2> missing.err; rc=$?
[ $rc = 2 ] && grep -q "sudo modprobe vcan" missing.err && ok "missing interface names the fix" || bad "missing: rc=$rc $(cat missing.err)"
ip link set vcan0 down
"$cotui" scan vcan0 2> down.err; rc=$?
[ $rc = 2 ] && grep -q "sudo ip link set vcan0 up" down.err && ok "down interface names the fix" || bad "down: rc=$rc $(cat down.err)"
ip link set vcan0 up

kill $peer 2>/dev/null
wait $peer 2>/dev/null
echo "$passed passed, $failed failed"
[ $failed = 0 ]
