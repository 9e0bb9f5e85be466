#!/usr/bin/env bash
# Installs what the test suite needs on a fresh Debian machine: real peers to test
# against (can-utils, Wireshark's tshark, the python canopen library, DuckDB for the Parquet
# tests, canopen-lens for `cotui diagnose`), tmux for the end-to-end TUI tests, jq for
# tests/vbus/e2e.sh, GNU time for the bounded-memory tests, a JRE and pyspark for the Spark check of the Parquet tables, and qemu + busybox for the real SocketCAN bus (tests/vbus/install.sh;
# tests/vbus/run.sh fetches the kernel itself).
# Idempotent and quiet when done.
set -euo pipefail

need_apt=()
for pkg in can-utils tshark tmux jq qemu-system-x86 busybox-static openjdk-17-jre-headless time; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "ok installed" || need_apt+=("$pkg")
done
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "install-test-deps: apt-get install ${need_apt[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  # tshark asks whether non-root users may capture; answer no without a prompt.
  echo "wireshark-common wireshark-common/install-setuid boolean false" | $SUDO debconf-set-selections
  $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

if ! python3 -c "import can, canopen, duckdb" 2>/dev/null; then
  echo "install-test-deps: pip install python-can canopen duckdb"
  python3 -m pip install -q "python-can>=4.3" "canopen>=2.3" "duckdb>=1.1"
fi

# asammdf: python-can's MF4Writer writes the MDF4 test files with it (tests/decode/formats_mf4.rs).
if ! python3 -c "import asammdf" 2>/dev/null; then
  echo "install-test-deps: pip install asammdf"
  python3 -m pip install -q --break-system-packages "asammdf>=8.0"
fi

# pyspark: local-mode Spark reads the Parquet tables (tests/decode/parquet_spark.rs).
if ! python3 -c "import pyspark" 2>/dev/null; then
  echo "install-test-deps: pip install pyspark"
  python3 -m pip install -q --break-system-packages pyspark
fi

# canopen-lens: a peer for `cotui diagnose` (tests/decode/diagnose_peer.rs compares incidents).
if ! command -v canopen-lens >/dev/null 2>&1; then
  echo "install-test-deps: pip install canopen-lens"
  python3 -m pip install -q "canopen-lens==0.5.1"
fi

# The rest of what the vbus guest needs (iproute2, kmod, xz-utils).
bash "$(dirname "$0")/../tests/vbus/install.sh"
