#!/usr/bin/env bash
# The project's one test command (README and .ci/run call exactly this).
# Installs the test peers, checks formatting and lints, runs every test, the end-to-end
# suite over a real kernel CAN stack in a qemu guest (tests/vbus/e2e.sh), then runs the
# decoder benchmark once so its figures appear in the log.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-test-deps.sh
cargo fmt --check
cargo clippy --all-targets --quiet -- -D warnings
cargo test --quiet
bash tests/vbus/e2e.sh
cargo build --release --quiet
./target/release/cotui bench --frames 1000000
./target/release/cotui bench --tui --frames 10000000
