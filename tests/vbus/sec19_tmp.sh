#!/usr/bin/env bash
# The end-to-end suite, run INSIDE the vbus guest by tests/vbus/e2e.sh (which builds
# everything on the host first):
#   VBUS_IFACES="vcan0 vcan1:fd" tests/vbus/run.sh tests/vbus/e2e_guest.sh COTUI SOCKETCAN_LIVE_TEST
# Every check runs host-built cotui against peers cotui did not write: can-utils
# (cangen, cansend, candump), the python canopen peers (peers/sdo_server.py node 5,
# peers/drive402.py node 2 (sections 2-5, stopped with sdo_server.py after section 5) and node 12
# (section 14); peers/dcf_node.py nodes 10 and 11 in section 15; peers/diag_node.py node 7 in
# section 16; peers/sdo_server.py node 21 in section 17) and tmux.
# Prints one line per check ("ok   ..." or "FAIL ...") and "N passed, N failed"; exits 1
# on any failure.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
[ "${VBUS_GUEST:-}" = 1 ] || { echo "e2e_guest.sh runs inside the guest: tests/vbus/e2e.sh" >&2; exit 2; }
[ $# = 2 ] || { echo "usage: $0 COTUI SOCKETCAN_LIVE_TEST" >&2; exit 2; }
cotui=$(realpath "$1")
live_test=$(realpath "$2")

passed=0
failed=0
t_start=$(date +%s.%N)
# ok/bad print the seconds since the script started, so slow checks show up in CI logs.
took() { awk -v a="$t_start" -v b="$(date +%s.%N)" 'BEGIN { printf "%5.1fs", b - a }'; }
ok() { echo "ok   $(took) $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $(took) $1"; failed=$((failed + 1)); }
# jq on a command's JSON output: j FILTER < out
j() { jq -r "$1" 2>/dev/null; }
# Runs cotui with a time limit; its stdout goes to $out, its stderr to $err, status to $rc.
c() {
    timeout 60 "$cotui" "$@" > cmd.out 2> cmd.err
    rc=$?
    out=$(cat cmd.out)
    err=$(cat cmd.err)
}
# Waits up to 10 s until process $1 has a socket open (a CAN recorder is listening).
wait_socket() { for _ in $(seq 100); do ls -l "/proc/$1/fd" 2> /dev/null | grep -q socket: && return 0; sleep 0.1; done; return 1; }
# Waits up to $2 tenths of a second for file $1 to contain $3.
wait_for() { for _ in $(seq "$2"); do grep -qF -- "$3" "$1" 2> /dev/null && return 0; sleep 0.1; done; return 1; }

work=$(mktemp -d)
cd "$work" || exit 1
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2> /dev/null; done
    tmux kill-server 2> /dev/null
    wait 2> /dev/null
}
trap cleanup EXIT
# ---- 19 trigger: record --trigger's window equals candump's frames in it ----------------
# cotui sim with one drive; cangen adds 200 frames/s (0x380, no CANopen node's object) so the
# window holds hundreds of frames; candump -L records everything; cotui record --trigger emcy
# keeps 2 s before and 1 s after; the drive is faulted on cotui sim's stdin. The window file
# must hold exactly candump's frames inside [start, end] of its sidecar: none lost between
# the ring and the file.
rm -rf trigwin; mkfifo trig.in
"$cotui" sim vcan0 --node 2=aimotor < trig.in > trigsim.out 2>&1 &
trigsim=$!
pids+=($trigsim)
exec 8> trig.in
wait_for trigsim.out 300 "commands on stdin" || bad "trigger: cotui sim start: $(cat trigsim.out)"
candump -L vcan0 > trigall.log 2> /dev/null &
trigdump=$!
wait_socket $trigdump
"$cotui" record vcan0 --listen-only --trigger emcy --pre 2s --post 1s --count 1 -o trigwin > trigrec.out 2>&1 &
trigrec=$!
wait_socket $trigrec
cangen vcan0 -g 5 -I 380 -L 8 -D i &
trigload=$!
sleep 3
echo "fault 2 0x2310" >&8
for _ in $(seq 100); do kill -0 $trigrec 2> /dev/null || break; sleep 0.1; done
wait $trigrec; trig_rc=$?
kill $trigload; wait $trigload 2> /dev/null
sleep 0.2; kill $trigdump; wait $trigdump 2> /dev/null
exec 8>&-; kill -TERM $trigsim; wait $trigsim
side=$(ls trigwin/*.json 2> /dev/null | head -1)
if [ "$trig_rc" = 0 ] && [ -n "$side" ]; then
    start=$(jq -r .start "$side"); end=$(jq -r .end "$side")
    awk -v a="$start" -v b="$end" '{ t = substr($1, 2, length($1) - 2) + 0; if (t >= a && t <= b) print $1, $3 }' trigall.log > trig_want.txt
    awk '{ print $1, $3 }' "trigwin/$(jq -r .file "$side")" > trig_got.txt
    n=$(wc -l < trig_got.txt)
    [ "$n" -gt 20 ] && cmp -s trig_want.txt trig_got.txt && [ "$(jq .frames "$side")" = "$n" ] &&
        ok "trigger: cotui record vcan0 --trigger emcy: the window ($n frames) equals candump's frames in [$start, $end]" ||
        bad "trigger: window of $n frames (sidecar: $(jq .frames "$side")) differs from candump's $(wc -l < trig_want.txt) in [$start, $end]: $(diff trig_want.txt trig_got.txt | head -5)"
else
    bad "trigger: record --trigger rc=$trig_rc, no window: $(cat trigrec.out)"
fi

t_end=$(date +%s.%N)
echo "$passed passed, $failed failed ($(awk -v a="$t_start" -v b="$t_end" 'BEGIN { printf "%.0f", b - a }') s in the guest)"
[ "$failed" = 0 ]
