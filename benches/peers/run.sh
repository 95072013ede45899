#!/usr/bin/env bash
# Side-by-side peer run: the same mechanism scene with SciPy's solve_ivp and
# with flicker, on this machine in one go. Not part of CI.
#   bash benches/peers/run.sh             SciPy against flicker
#   bash benches/peers/run.sh --heyoka    heyoka against flicker's Taylor method
#   bash benches/peers/run.sh --friction  dry friction: sign() against SciPy's tanh smoothing
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
venv="$top/target/peers-venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet numpy scipy
fi
(cd "$top" && cargo build --release --quiet)
if [ "${1:-}" = "--friction" ]; then
  shift
  exec "$venv/bin/python" "$top/benches/peers/scipy_friction.py" --flicker "$top/target/release/flicker" "$@"
fi
if [ "${1:-}" = "--heyoka" ]; then
  shift
  "$venv/bin/python" -c "import heyoka" 2>/dev/null || "$venv/bin/pip" install --quiet heyoka
  exec "$venv/bin/python" "$top/benches/peers/heyoka_mechanism.py" --flicker "$top/target/release/flicker" "$@"
fi
"$venv/bin/python" "$top/benches/peers/scipy_mechanism.py" --flicker "$top/target/release/flicker" "$@"
