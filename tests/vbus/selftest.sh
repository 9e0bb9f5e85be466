#!/usr/bin/env bash
# Host-side test of the vbus harness (what CI runs): boots the guest four times.
#   tests/vbus/selftest.sh
# 1. smoke.sh in the guest (kernel CAN traffic, the python peers) on "vcan0 vcan1:fd";
# 2. a failing command's status comes back (exit 7); 3. an unknown command gives 127;
# 4. VBUS_TIMEOUT gives 124. Prints "N passed, N failed"; exits 1 on any failure.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
run="$here/run.sh"
passed=0
failed=0
expect_status() {
    local want=$1 what=$2
    shift 2
    local t0=$SECONDS
    "$@"
    local got=$?
    if [ "$got" = "$want" ]; then
        echo "ok   $what (status $got, $((SECONDS - t0))s)"
        passed=$((passed + 1))
    else
        echo "FAIL $what: status $got, want $want"
        failed=$((failed + 1))
    fi
}

export VBUS_TIMING=1
VBUS_IFACES="vcan0 vcan1:fd" expect_status 0 "smoke.sh in the guest" "$run" "$here/smoke.sh"
expect_status 7 "a failing command's status" "$run" sh -c 'test -d /proc/net/can && exit 7'
expect_status 127 "an unknown command" "$run" vbus-no-such-command
VBUS_TIMEOUT=3 expect_status 124 "VBUS_TIMEOUT" "$run" sleep 600

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
