#!/usr/bin/env bash
# Side-by-side peer run: the same mechanism scene with SciPy's solve_ivp and
# with flicker, on this machine in one go. Not part of CI.
#   bash benches/peers/run.sh
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
venv="$top/target/peers-venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet numpy scipy
fi
(cd "$top" && cargo build --release --quiet)
"$venv/bin/python" "$top/benches/peers/scipy_mechanism.py" --flicker "$top/target/release/flicker" "$@"
