#!/usr/bin/env bash
# Side-by-side peer run: the same mechanism scene with SciPy's solve_ivp and
# with flicker, on this machine in one go. Not part of CI.
#   bash benches/peers/run.sh             SciPy against flicker
#   bash benches/peers/run.sh --heyoka    heyoka against flicker's Taylor method
#   bash benches/peers/run.sh --friction  dry friction: sign() against SciPy's tanh smoothing
#   bash benches/peers/run.sh --heyoka-cases [N]
#                                         heyoka against flicker on four automata
#                                         (benches/peers/heyoka/README.md), N runs each
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
if [ "${1:-}" = "--heyoka-cases" ]; then
  "$venv/bin/python" -c "import heyoka, mpmath" 2>/dev/null || "$venv/bin/pip" install --quiet heyoka mpmath
  n="${2:-7}"
  cd "$top"
  for case in case1_mechanism case2_henon_heiles case2b_hh_noevents case2d_hh_tangent case3_pendulum case4_forced; do
    FLICKER="$top/target/release/flicker" "$venv/bin/python" "$top/benches/peers/heyoka/$case.py" "$n"
  done
  exit 0
fi
if [ "${1:-}" = "--heyoka" ]; then
  shift
  "$venv/bin/python" -c "import heyoka" 2>/dev/null || "$venv/bin/pip" install --quiet heyoka
  exec "$venv/bin/python" "$top/benches/peers/heyoka_mechanism.py" --flicker "$top/target/release/flicker" "$@"
fi
"$venv/bin/python" "$top/benches/peers/scipy_mechanism.py" --flicker "$top/target/release/flicker" "$@"
