#!/usr/bin/env bash
# The Rust core vs Pinocchio's C++ on the same UR5 and Panda models (benchmark only, never in CI).
#   pip install pin cmeel-eigen      # Pinocchio's headers ship in the `pin` wheel, Eigen's in cmeel-eigen
#   benches/cpp/compare_core.sh
# Pinocchio is built header-only with -O3 -march=native (see the peer notes); the Rust bench with
# -C target-cpu=native in a separate target folder. Prints the ratio C++ time / Rust time.
set -euo pipefail
cd "$(dirname "$0")/../.."
SP=$(python -c "import site; print(site.getsitepackages()[0])")
INC="$SP/cmeel.prefix/include"
OUT=${KINEDYN_BENCH_DIR:-/tmp/kinedyn-cpp-bench}
mkdir -p "$OUT"
if [ ! -x "$OUT/pinocchio_dynamics" ] || [ benches/cpp/pinocchio_dynamics.cpp -nt "$OUT/pinocchio_dynamics" ]; then
  echo "compiling Pinocchio (several minutes)..." >&2
  g++ -O3 -march=native -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -I"$INC" -I"$INC/eigen3" \
    benches/cpp/pinocchio_dynamics.cpp -o "$OUT/pinocchio_dynamics"
fi
"$OUT/pinocchio_dynamics" > "$OUT/cpp.txt"
RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$OUT/target" \
  cargo bench -p kinedyn-core --bench core -- "rnea|crba|/aba|coriolis|gravity|mass_matrix_inverse" > "$OUT/rust.txt" 2>&1
python - "$OUT/cpp.txt" "$OUT/rust.txt" <<'PY'
import re, sys
cpp = dict(line.split() for line in open(sys.argv[1]) if "/check" not in line)
unit = {"ns": 1.0, "µs": 1e3, "us": 1e3, "ms": 1e6}
rust = {}
name = None
for line in open(sys.argv[2]):
    m = re.match(r"^(\S+/\S+)\s*(time:.*)?$", line.strip())
    if m and "/" in m.group(1) and not line.startswith(" "):
        name = m.group(1)
    t = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", line)
    if t and name:
        rust[name] = float(t.group(1)) * unit[t.group(2)]
print(f"{'':28s} {'Pinocchio C++':>14s} {'kinedyn-core':>13s}   speed-up")
for key, c in cpp.items():
    if key in rust:
        print(f"{key:28s} {float(c):11.0f} ns {rust[key]:10.0f} ns   {float(c) / rust[key]:6.2f}x")
PY
